// The valve's dictionary as a master sees it after power-on (UMAX020411A §3.2-3.4), its factory
// state (no fault with the simulated pins at their defaults) and "time is events": a node with
// steady inputs arms no timer of its own.
#include "tests/unit/valve/valve_fixture.hpp"

namespace canfleet::devices::valve::test {
namespace {

class ValveDictionaryTest : public ValveTest {};

// §3.2.1, §3.2.11: device type and identity.
TEST_F(ValveDictionaryTest, IdentityObjects) {
  EXPECT_EQ(Read(0x1000, 0), 0xE01F0194);
  EXPECT_EQ(Read(0x1018, 1), 0x00000055);
  EXPECT_EQ(Read(0x1018, 2), 0xAA020411);
  EXPECT_EQ(Read(0x1018, 3), 0x00010000);
}

// §3.3.3, §3.3.4, §3.4.4, §3.3.20: input and output defaults (UI voltage / DI digital PWM-type,
// 0-5 V range; OUT1-8 current, DO1-4 digital).
TEST_F(ValveDictionaryTest, InputAndOutputDefaults) {
  EXPECT_EQ(Read(0x6110, 1), 40);
  EXPECT_EQ(Read(0x6110, 8), 10000);
  EXPECT_EQ(Read(0x6112, 7), 1);
  EXPECT_EQ(Read(0x6112, 12), 10);
  EXPECT_EQ(Read(0x2100, 1), 0);  // README-dictionary.md 22: 0 = 0-5 V, not the printed 2
  EXPECT_EQ(Read(0x6310, 8), 20);
  EXPECT_EQ(Read(0x6310, 9), 1000);
  EXPECT_EQ(Read(0x2341, 12), 12);
  EXPECT_EQ(Read(0x1003, 0), 0);
}

// §1.3, §3.3.8: with the pins mid-range (2500 mV) the inputs read their field values at once.
TEST_F(ValveDictionaryTest, InputsReadTheSimulatedPins) {
  for (std::uint8_t sub = 1; sub <= 7; ++sub) {
    EXPECT_EQ(Read(0x7100, sub, true), 2500) << int(sub);
    EXPECT_EQ(Read(0x7130, sub, true), 2500) << int(sub);
  }
  EXPECT_EQ(Read(0x7100, 8), 0);  // DI1 digital, pin open, no pull: OFF
}

// §3.4.99, §3.4.104: supply and temperature as REAL32 (24.0 V = 41C00000h, 40.0 degC = 42200000h).
TEST_F(ValveDictionaryTest, SupplyAndTemperatureAreReal32) {
  EXPECT_EQ(Read(0x5020, 0), 0x41C00000);
  EXPECT_EQ(Read(0x5030, 0), 0x42200000);
}

// §8 of the digest / README: the manual's defaults would fault an open input at 0 V after 1 s; the
// simulated pins default mid-range, so an idle node at factory defaults raises nothing.
TEST_F(ValveDictionaryTest, IdleNodeAtFactoryDefaultsRaisesNoFault) {
  Advance(5s);
  EXPECT_TRUE(Frames("085#").empty());
  EXPECT_EQ(Read(0x1001, 0), 0);
  EXPECT_EQ(Read(0x1003, 0), 0);
}

// Design decision 10: steady inputs, no timer; one input change runs the blocks, then sleep again.
TEST_F(ValveDictionaryTest, SteadyNodeSleepsAndWakesOnInputChanges) {
  Advance(500ms);  // the first feedback windows after power-on
  EXPECT_TRUE(valve().Idle());
  const auto runs = valve().Runs();
  Advance(10s);
  EXPECT_EQ(valve().Runs(), runs);
  SetNumber("IN1.voltage_mV", 3000);
  EXPECT_FALSE(valve().Idle());
  Advance(5ms);
  EXPECT_EQ(Read(0x7100, 1, true), 3000);
  EXPECT_TRUE(valve().Idle());
  EXPECT_LE(valve().Runs() - runs, 3u);
}

// §3.4.109: 5555h TRUE boots into operational without a master (here after a reset
// communication, which keeps the application objects).
TEST_F(ValveDictionaryTest, StartInOperational) {
  Write(0x5555, 0, 1, 1);
  Send("000#8205");
  EXPECT_EQ(stack().State(), canopen::NmtState::kOperational);
  Write(0x5555, 0, 0, 1);
  Send("000#8205");
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
}

// §3.2.15: TPDO1/TPDO2 every 100 ms in operational with 7100h.1-8 (little-endian INTEGER16);
// §4: a disabled input sends "no CAN messages associated with that channel": TPDO1 carries only
// UI1-UI4, so with all four off it stays off the bus while TPDO2 goes on.
TEST_F(ValveDictionaryTest, TpdosAndDisabledInputs) {
  Start();
  Frames();
  Advance(100ms);
  EXPECT_EQ(Frames("185#"), std::vector<std::string>{"185#C409C409C409C409"});
  for (std::uint8_t sub = 1; sub <= 4; ++sub)
    Write(0x6112, sub, 0, 1);
  Frames();
  Advance(200ms);
  EXPECT_TRUE(Frames("185#").empty());
  Advance(100ms);
  EXPECT_EQ(Frames("285#").size(), 1u);
}

// §3.2.4 / reset node: the node boots without errors and its blocks start over; a condition still
// present is found again after its delay.
TEST_F(ValveDictionaryTest, ResetNodeStartsOver) {
  SetNumber("IN2.voltage_mV", 0);
  Advance(1100ms);
  EXPECT_EQ(Read(0x1003, 0), 1);
  Send("000#8105");
  Frames();
  Advance(2ms);
  EXPECT_EQ(Read(0x1003, 0), 0);
  EXPECT_EQ(Read(0x1001, 0), 0);
  Advance(1000ms);
  EXPECT_EQ(Read(0x1003, 1), 0x4002F001);
}

}  // namespace
}  // namespace canfleet::devices::valve::test
