// The sequence issue 19 asks of the product, as one frame script on simulated time (the system
// test under `canfleet up` drives the same with real processes): supply on by CAN (§1.2.1 Table 2,
// RPDO1), load stepped up into the current limit (§1.2.1.3 Fig. 2), input voltage dropped below
// threshold 1 (§1.2.3: failure flags, EMCY FF04h, latch with 2320h = 1), Quit Failure (Table 6),
// delayed shutdown without and with the acknowledge (§1.2.1.1, RPDO3).
#include "tests/unit/power_supply/ps_fixture.hpp"

namespace canfleet::devices::test {
namespace {

TEST_F(PsTest, IssueSequenceOnLimitFailureQuitAndShutdowns) {
  Write(0x2320, 0, 1, 1);       // latch DS-453 faults (§2.4.9)
  Write(0x6205, 12, 15500, 4);  // current threshold 2 above the 15 A limit, return alike (Table 5)
  Write(0x6205, 42, 15500, 4);
  Write(0x2302, 0, 1000, 4);        // base shutdown delay
  Write(0x2303, 0, 100, 4);         // acknowledged shutdown delay
  Write(0x1402, 1, 0x4000047F, 4);  // RPDO3 (2301h) exists
  Send("000#017F");
  Advance(1ms);

  // On by CAN.
  Send("27F#FDFF");
  Advance(2ms);
  EXPECT_TRUE(io().Bool("PS.output_on"));
  EXPECT_EQ(Read(0x6204, 1), 24000);

  // Load stepped up: 1 ohm asks 24 A, the supply holds 15 A at 15 V.
  SetNumber("LOAD.resistance_ohm", 1.0);
  Advance(2ms);
  EXPECT_TRUE(io().Bool("PS.current_limited"));
  EXPECT_EQ(Read(0x6204, 2), 15000);
  EXPECT_EQ(Read(0x6204, 1), 15000);
  SetNumber("LOAD.resistance_ohm", 24.0);

  // Input dropped below 6114h/611Ah (9 V) with the default 200 ms repeating average: 6113h shows
  // it within 200 ms, then 6119h.1 (100 ms) and 6013h.1 (100 ms).
  Frames();
  SetNumber("VIN.voltage_mV", 8800);
  Advance(400ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{Emcy(0xFF04, 0x01, 0x00, 0x00)});
  EXPECT_EQ(Read(0x6112, 5), 0xFFF0FFF1);
  EXPECT_EQ(State(), "fault_latched");
  EXPECT_FALSE(io().Bool("PS.output_on"));

  // Input back: the error resets, the latch holds until Quit Failure.
  SetNumber("VIN.voltage_mV", 24000);
  Advance(250ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{EmcyReset()});
  EXPECT_FALSE(io().Bool("PS.output_on"));
  Send("27F#FDFC");
  Advance(1ms);
  EXPECT_TRUE(io().Bool("PS.output_on"));

  // Delayed shutdown without acknowledge: F001h, off 1000 ms later.
  Send("27F#FCFF");
  Advance(1ms);
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{Emcy(0xF001, 0x01, 0x00, 0x20)});
  Advance(999ms);
  EXPECT_TRUE(io().Bool("PS.output_on"));
  Advance(1ms);
  EXPECT_FALSE(io().Bool("PS.output_on"));
  EXPECT_EQ(Frames("0FF#"), std::vector<std::string>{EmcyReset()});

  // With the acknowledge: off 2303h = 100 ms after it.
  Send("27F#FDFF");
  Advance(1ms);
  Send("27F#FCFF");
  Advance(300ms);
  Send("47F#01");
  Advance(99ms);
  EXPECT_TRUE(io().Bool("PS.output_on"));
  Advance(1ms);
  EXPECT_FALSE(io().Bool("PS.output_on"));
}

}  // namespace
}  // namespace canfleet::devices::test
