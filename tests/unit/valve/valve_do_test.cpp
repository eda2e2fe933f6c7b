// The digital output block (UMAX020411A §1.4, Table 12-13, §3.3.16-3.3.18, §3.4.19-3.4.25): 6200h
// RPDO control, polarity (normal, inverse, latched, blink), the 2224h/2225h delay, the hotshot
// profile (Figure 9) and the 6250h/6260h fault state.
#include "tests/unit/valve/valve_fixture.hpp"

namespace canfleet::devices::valve::test {
namespace {

class ValveDoTest : public ValveTest {
 protected:
  void SetUp() override {
    SilenceTpdos();
    Start();
    Frames();
  }
  /// RPDO4 (505h): 6200h.1 (OUT1-8 bits), 6200h.2 (DO1-DO4 bits).
  void Rpdo4(std::uint8_t outs, std::uint8_t dos) { Send("505#" + LeHex(outs, 1) + LeHex(dos, 1)); }
  bool On(std::string_view output) { return io().Bool(std::string(output) + ".on"); }
};

// §1.4, §3.3.16: DO1 follows bit 0 of 6200h.2 (CANopen message 9, its factory control).
TEST_F(ValveDoTest, RpdoSwitchesTheOutput) {
  Rpdo4(0, 0x01);
  Advance(2ms);
  EXPECT_TRUE(On("OUT9"));
  EXPECT_FALSE(On("OUT10"));
  EXPECT_EQ(Read(0x7330, 9), 1);
  EXPECT_EQ(Out("OUT9.current_mA"), 1000);
  Advance(200ms);
  EXPECT_EQ(Read(0x2370, 9), 1);  // §1.4: 2370h carries the drive state
  Rpdo4(0, 0x0A);
  Advance(2ms);
  EXPECT_FALSE(On("OUT9"));
  EXPECT_TRUE(On("OUT10"));
  EXPECT_TRUE(On("OUT12"));
}

// Table 12, 1 "inverse".
TEST_F(ValveDoTest, InversePolarity) {
  Write(0x2210, 10, 1, 1);
  Advance(2ms);
  EXPECT_TRUE(On("OUT10"));
  Rpdo4(0, 0x02);
  Advance(2ms);
  EXPECT_FALSE(On("OUT10"));
}

// Table 12, 2 "latched": OFF -> ON of the logic state toggles the drive; ON -> OFF changes nothing.
TEST_F(ValveDoTest, LatchedPolarity) {
  Write(0x2210, 11, 2, 1);
  Rpdo4(0, 0x04);
  Advance(2ms);
  EXPECT_TRUE(On("OUT11"));
  Rpdo4(0, 0);
  Advance(2ms);
  EXPECT_TRUE(On("OUT11"));
  Rpdo4(0, 0x04);
  Advance(2ms);
  EXPECT_FALSE(On("OUT11"));
}

// Table 12, 3 and §3.4.23: while ON, on for 2223h ms then off for 2223h ms; the node wakes at each
// toggle only.
TEST_F(ValveDoTest, BlinkAt2223h) {
  Write(0x2210, 12, 3, 1);
  Write(0x2223, 12, 500, 2);
  Rpdo4(0, 0x08);
  Advance(250ms);  // the logic turned ON at +1 ms
  EXPECT_TRUE(On("OUT12"));
  Advance(500ms);
  EXPECT_FALSE(On("OUT12"));
  Advance(500ms);
  EXPECT_TRUE(On("OUT12"));
  const auto runs = valve().Runs();
  Advance(2000ms);
  EXPECT_LE(valve().Runs() - runs, 60u);  // toggles and feedback windows, not 2000 ticks
  Rpdo4(0, 0);
  Advance(2ms);
  EXPECT_FALSE(On("OUT12"));
}

// §3.4.24/3.4.25: with 2225h = 1 (ON) the ON edge waits 2224h ms, the OFF edge acts at once;
// with 2225h = 0 the other way round.
TEST_F(ValveDoTest, DelayOnTheEdgeOf2225h) {
  Write(0x2224, 9, 300, 2);
  Rpdo4(0, 0x01);
  Advance(300ms);
  EXPECT_FALSE(On("OUT9"));
  Advance(2ms);
  EXPECT_TRUE(On("OUT9"));
  Rpdo4(0, 0);
  Advance(2ms);
  EXPECT_FALSE(On("OUT9"));
  Write(0x2225, 9, 0, 1);
  Rpdo4(0, 0x01);
  Advance(2ms);
  EXPECT_TRUE(On("OUT9"));
  Rpdo4(0, 0);
  Advance(200ms);
  EXPECT_TRUE(On("OUT9"));
  Advance(102ms);
  EXPECT_FALSE(On("OUT9"));
}

// §1.4 Figure 9, §3.4.20-3.4.22: a hotshot output drives 2220h for 2222h ms, then holds 2221h.
TEST_F(ValveDoTest, HotshotProfile) {
  Write(0x6310, 1, 1020, 2);  // OUT1 hotshot: CANopen message 1 is now bit 0 of 6200h.1
  Rpdo4(0x01, 0);
  Advance(500ms);
  EXPECT_TRUE(On("OUT1"));
  EXPECT_EQ(Out("OUT1.current_mA"), 2000);
  Advance(502ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 500);
  Rpdo4(0, 0);
  Advance(2ms);
  EXPECT_EQ(Out("OUT1.current_mA"), 0);
  EXPECT_FALSE(On("OUT1"));
}

// §1.4: the hotshot uses the output timer, so "blinking does not apply": it acts as normal on/off.
TEST_F(ValveDoTest, HotshotDoesNotBlink) {
  Write(0x6310, 2, 1020, 2);
  Write(0x2210, 2, 3, 1);
  Write(0x2223, 2, 100, 2);
  Rpdo4(0x02, 0);
  Advance(150ms);
  EXPECT_TRUE(On("OUT2"));
}

// Table 13 / §3.3.17-3.3.18: a faulted control input applies 6260h (factory ON); 6250h = 0 keeps
// the last state.
TEST_F(ValveDoTest, FaultStateOnAFaultedInput) {
  Write(0x2340, 10, 2, 1);  // DO2 from UI1: ON at or above the middle of 7320h..7322h (0..1)
  Write(0x2341, 10, 1, 1);
  Write(0x2112, 1, 0, 2);
  Write(0x6260, 10, 0, 1);
  Advance(2ms);
  EXPECT_TRUE(On("OUT10"));  // 2500 mV
  SetNumber("IN1.voltage_mV", 100);
  Advance(2ms);
  EXPECT_FALSE(On("OUT10"));  // 6260h = OFF
  Write(0x6260, 10, 1, 1);
  Advance(2ms);
  EXPECT_TRUE(On("OUT10"));
  Write(0x6250, 10, 0, 1);
  SetNumber("IN1.voltage_mV", 2500);
  Advance(2ms);
  Rpdo4(0, 0);
  Write(0x2340, 10, 1, 1);  // back to the RPDO, which says OFF
  Write(0x2341, 10, 10, 1);
  Advance(2ms);
  EXPECT_FALSE(On("OUT10"));
  Write(0x2340, 10, 2, 1);
  Write(0x2341, 10, 1, 1);
  SetNumber("IN1.voltage_mV", 100);
  Advance(2ms);
  EXPECT_FALSE(On("OUT10"));  // maintained
}

// §1.4: DO1-DO4 can only be 1000 or 0 (disabled).
TEST_F(ValveDoTest, DisabledOutputStaysOff) {
  Write(0x6310, 9, 0, 2);
  Rpdo4(0, 0x01);
  Advance(2ms);
  EXPECT_FALSE(On("OUT9"));
}

}  // namespace
}  // namespace canfleet::devices::valve::test
