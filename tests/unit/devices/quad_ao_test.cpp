// The Quad's proportional output block (AX020506 §2.6, §3.5): CAN control through 7330h (RPDO1)
// and through 7F50h/6F52h with 7320h-7323h scaling, input control through the six current
// profiles, ramps over simulated time, dither, invalid values.
#include "node/devices/quad_controller/ao_profile.hpp"
#include "tests/unit/devices/quad_fixture.hpp"

namespace canfleet::devices::test {
namespace {

using quad::ProfileCurrent;
using quad::ProfileCurrents;
using quad::ProfileInputs;

class QuadAoTest : public QuadTest {
 protected:
  double Current(int n) { return io().Number("OUT" + std::to_string(n) + ".current_mA"); }
};

// §3.1.1 RPDO1 maps 7330h.1-4; §3.5.10 30A0h default 2: no ramps under CAN control; §3.5.12 the
// measured current 30C0h goes out in TPDO4.
TEST_F(QuadAoTest, Rpdo1SetsTheCurrentsAndTpdo4ReportsThem) {
  Start();                       // t = 1 ms
  Send("205#E803D007F4010000");  // 1000, 2000, 500, 0 mA
  Advance(1ms);
  EXPECT_EQ(Current(1), 1000);
  EXPECT_EQ(Current(2), 2000);
  EXPECT_EQ(Current(3), 500);
  EXPECT_EQ(Current(4), 0);
  EXPECT_TRUE(io().Bool("OUT1.on"));
  EXPECT_FALSE(io().Bool("OUT4.on"));
  Frames();
  Advance(98ms);  // t = 100 ms: the event timers
  EXPECT_EQ(Frames("485#"), std::vector<std::string>{"485#E803D007F4010000"});
}

// §3.5.20: the field value is a current in mA; the outputs are rated 0-2000 mA.
TEST_F(QuadAoTest, FieldValuesBeyondTheRatingAreClamped) {
  Start();
  Send("205#D0070000FFFF0000");  // 2000, 0, -1, 0
  Write(0x7330, 1, 2500, 2);
  Advance(1ms);
  EXPECT_EQ(Current(1), 2000);
  EXPECT_EQ(Current(3), 0);
}

// §3.5.8-10: with 30A0h = 1 ramps apply to CAN control too; 3080h is the time from 0 to 2000 mA
// (the highest current under CAN control), 3090h from 2000 mA to 0.
TEST_F(QuadAoTest, RampsFollowTheRampTimesOverSimulatedTime) {
  Write(0x30A0, 1, 1, 1);
  Write(0x3090, 1, 500, 2);
  Start();
  Send("205#E803000000000000");  // POUT1 → 1000 mA
  Advance(375ms);                // 375 ms × 2000 mA / 1500 ms
  EXPECT_NEAR(Current(1), 500, 0.01);
  EXPECT_EQ(Read(0x30C0, 1), 500);
  Advance(375ms);
  EXPECT_NEAR(Current(1), 1000, 0.01);
  Advance(100ms);
  EXPECT_NEAR(Current(1), 1000, 0.01);
  Send("205#0000000000000000");
  Advance(125ms);  // 125 ms × 2000 mA / 500 ms
  EXPECT_NEAR(Current(1), 500, 0.01);
  Advance(125ms);
  EXPECT_EQ(Current(1), 0);
}

// §3.5.10: 0 = no ramps even for input control.
TEST_F(QuadAoTest, RampControlZeroStepsAtOnce) {
  Write(0x30A0, 2, 0, 1);
  Write(0x3010, 2, 2, 1);  // POUT2 ← AIN2
  SetNumber("IN2.voltage_mV", 4500);
  Advance(10ms);
  EXPECT_EQ(Current(2), 1500);
}

// §2.6, §3.5.1-2: an input drives the output through its profile, in pre-operational as well;
// ramps (30A0h = 2) apply: 3080h is the time from 0 to the highest profile current (1500 mA).
TEST_F(QuadAoTest, AnInputDrivesTheOutputThroughItsProfileWithRamps) {
  Write(0x3010, 1, 1, 1);             // POUT1 ← AIN1, single profile single slope
  SetNumber("IN1.voltage_mV", 2500);  // (2500 − 500) / (4500 − 500) × 1500 = 750 mA
  Advance(10ms);                      // first sample and first step: 1 mA
  EXPECT_NEAR(Current(1), 1, 0.01);
  Advance(374ms);
  EXPECT_NEAR(Current(1), 375, 0.01);
  Advance(400ms);
  EXPECT_EQ(Current(1), 750);
  SetNumber("IN1.voltage_mV", 4700);  // above 2070h: the maximum current
  Advance(1000ms);
  EXPECT_EQ(Current(1), 1500);
}

// §3.5.1 note 1: the control input must be in normal operation.
TEST_F(QuadAoTest, InputControlNeedsNormalMode) {
  Write(0x30A0, 1, 0, 1);
  Write(0x3010, 1, 1, 1);
  Write(0x6112, 1, 20, 1);
  SetNumber("IN1.voltage_mV", 4500);
  Advance(20ms);
  EXPECT_EQ(Current(1), 0);
}

// §3.5.23-24: a received PV is used only when 6F52h validates it; it is copied to 7300h, scaled
// by 7320h-7323h into 7330h, and 6F52h returns to 0.
TEST_F(QuadAoTest, ReceivedPvIsUsedOnlyWhenValidated) {
  Start();
  Write(0x7322, 2, 100, 2);   // PV2 100 %
  Write(0x7323, 2, 2000, 2);  // FV2 2000 mA (PV1 = FV1 = 0)
  Write(0x7F50, 2, 50, 2);
  Advance(1ms);
  EXPECT_EQ(Read(0x7300, 2), 0);
  EXPECT_EQ(Current(2), 0);
  Write(0x6F52, 2, 1, 1);
  // While validated, 7330h may not be written directly (§3.5.20).
  EXPECT_EQ(TryWrite(0x7330, 2, 100, 2), SdoAborted(0x7330, 2, 0x08000022));
  Advance(1ms);
  EXPECT_EQ(Read(0x7300, 2), 50);
  EXPECT_EQ(Read(0x7330, 2), 1000);
  EXPECT_EQ(Read(0x6F52, 2), 0);
  EXPECT_EQ(Current(2), 1000);
  Write(0x7F50, 2, 80, 2);  // not validated again: ignored
  Advance(1ms);
  EXPECT_EQ(Current(2), 1000);
}

// §2.6 "7F50h can be mapped to a PDO": an RPDO carrying the PV and its status, remapped with the
// CiA 301 procedure.
TEST_F(QuadAoTest, AnRpdoCarryingPvAndStatusDrivesTheOutput) {
  Write(0x1402, 1, 0x80000405, 4);
  Write(0x1602, 0, 0, 1);
  Write(0x1602, 1, 0x7F500310, 4);
  Write(0x1602, 2, 0x6F520308, 4);
  Write(0x1602, 0, 2, 1);
  Write(0x1402, 1, 0x405, 4);
  Start();
  Send("405#DC0501");  // 7F50h.3 = 1500, 6F52h.3 = 1
  Advance(1ms);
  EXPECT_EQ(Current(3), 1500);  // default scaling is the identity
  Send("405#E80300");           // not validated
  Advance(1ms);
  EXPECT_EQ(Current(3), 1500);
}

// §2.6: dither rides on the current whatever the control; 3070h = 0 switches it off.
TEST_F(QuadAoTest, DitherIsSuperimposedWhileTheOutputDrivesCurrent) {
  Write(0x3070, 1, 100, 2);
  Write(0x3060, 1, 300, 2);
  Start();
  EXPECT_EQ(io().Number("OUT1.dither_mA"), 0);
  Send("205#E803000000000000");
  Advance(1ms);
  EXPECT_EQ(io().Number("OUT1.dither_mA"), 100);
  EXPECT_EQ(io().Number("OUT1.dither_Hz"), 300);
  EXPECT_EQ(Read(0x30C0, 1), 1000);                                          // the mean current
  EXPECT_EQ(TryWrite(0x3060, 1, 40, 2), SdoAborted(0x3060, 1, 0x06090032));  // 50-400 Hz
}

// §2.6 "Manufacturer dither objects 3060h (frequency) and 3070h (amplitude) apply regardless of
// which control signal is selected": an input-controlled output dithers too. §3.5.6-7: the dither
// belongs to the proportional outputs, so a POUT switched as a digital output (6310h = 1000) has
// none. The waveform itself is not sampled (README choice 20): amplitude and frequency are
// reported, 30C0h is the mean current.
TEST_F(QuadAoTest, DitherAppliesUnderInputControlButNotToADigitalOutput) {
  Write(0x30A0, 1, 0, 1);             // no ramps
  Write(0x3010, 1, 1, 1);             // POUT1 <- AIN1, single profile
  Write(0x3070, 1, 250, 2);           // 250 mA
  Write(0x3060, 1, 80, 2);            // 80 Hz
  SetNumber("IN1.voltage_mV", 4500);  // 2070h: the maximum current, 1500 mA
  Advance(10ms);
  EXPECT_EQ(Current(1), 1500);
  EXPECT_EQ(io().Number("OUT1.dither_mA"), 250);
  EXPECT_EQ(io().Number("OUT1.dither_Hz"), 80);
  EXPECT_EQ(Read(0x30C0, 1), 1500);

  Write(0x6310, 1, 1000, 2);  // §3.5.15: POUT1 becomes a digital output
  Write(0x3001, 1, 1, 1);     // §3.4.1: controlled by AIN1 as ON/OFF (4500 mV >= 2002h 3500 mV)
  Advance(10ms);
  EXPECT_TRUE(io().Bool("OUT1.on"));
  EXPECT_EQ(Current(1), 1000);  // the load's current
  EXPECT_EQ(io().Number("OUT1.dither_mA"), 0);
  EXPECT_EQ(io().Number("OUT1.dither_Hz"), 0);
}

// §1.1 "Total current consumption of all the outputs combined must not exceed 6A" and Appendix A
// "The maximum total current draw on the power supply pins is 6 Amps": a rating for whoever wires
// the loads. The manual gives the controller no reaction to it (no limiting, no EMCY code in
// §4.1), so four POUTs at 2 A and DOUT on are all driven as commanded, without a fault
// (README choice 21).
TEST_F(QuadAoTest, TheSixAmpereTotalIsARatingNotALimit) {
  Start();
  Send("205#D007D007D007D007");  // RPDO1: 4 x 2000 mA
  Send("305#10");                // RPDO2: 6200h bit 4, DOUT on
  Advance(1ms);
  for (int n = 1; n <= 4; ++n)
    EXPECT_EQ(Current(n), 2000) << "OUT" << n;
  EXPECT_TRUE(io().Bool("OUT5.on"));
  Advance(2000ms);  // longer than every error delay
  EXPECT_TRUE(Frames("085#").empty());
  EXPECT_EQ(Read(0x1001, 0), 0);
  EXPECT_EQ(Current(4), 2000);
}

// §4.2: SDO writes that control outputs are refused in pre-operational; §3.5.20 an open load
// draws no current although the driver is on.
TEST_F(QuadAoTest, PreOperationalRefusesOutputWritesAndAnOpenLoadDrawsNothing) {
  EXPECT_EQ(TryWrite(0x7330, 1, 500, 2), SdoAborted(0x7330, 1, 0x08000022));
  EXPECT_EQ(TryWrite(0x7F50, 1, 500, 2), SdoAborted(0x7F50, 1, 0x08000022));
  Start();
  SetEnum("OUT1.load", "open");
  Write(0x7330, 1, 500, 2);
  Advance(1ms);
  EXPECT_TRUE(io().Bool("OUT1.on"));
  EXPECT_EQ(Current(1), 0);
  EXPECT_EQ(Read(0x30C0, 1), 0);
}

// §3.5.1, §3.5.2, §3.5.10: values not listed → SDO abort, previous value kept.
TEST_F(QuadAoTest, InvalidControlResponseOrRampControlIsRefused) {
  EXPECT_EQ(TryWrite(0x3010, 1, 7, 1), SdoAborted(0x3010, 1, 0x06090030));
  EXPECT_EQ(TryWrite(0x3020, 2, 6, 1), SdoAborted(0x3020, 2, 0x06090030));
  EXPECT_EQ(TryWrite(0x30A0, 3, 3, 1), SdoAborted(0x30A0, 3, 0x06090030));
  EXPECT_EQ(TryWrite(0x3050, 4, 2001, 2), SdoAborted(0x3050, 4, 0x06090031));
  // 30A0h is UNSIGNED8 (object table; the detail page says UNSIGNED16, see README.md).
  EXPECT_EQ(TryWrite(0x30A0, 3, 1, 2), SdoAborted(0x30A0, 3, 0x06070012));
  EXPECT_EQ(Read(0x3010, 1), 0);
  EXPECT_EQ(Read(0x3020, 2), 0);
  EXPECT_EQ(Read(0x30A0, 3), 2);
  Write(0x3020, 2, 5, 1);
}

// The six profiles of §2.6 (graphs "Single Profile", "Dual Profile A", "Dual Profile B") with the
// default points of §3.3.2-7 (AIN, mV) and currents of §3.5.3-5.
class AoProfileTest : public ::testing::Test {
 protected:
  const ProfileInputs in{500, 1400, 2300, 2700, 3600, 4500};
  const ProfileCurrents out{0, 750, 1500};
  int At(std::uint8_t response, int mv) const { return ProfileCurrent(response, mv, in, out); }
};

TEST_F(AoProfileTest, SingleProfileRisesFromMinimumToMaximum) {
  EXPECT_EQ(At(0, 300), 0);  // below 2020h: the minimum current
  EXPECT_EQ(At(0, 500), 0);
  EXPECT_EQ(At(0, 2500), 750);
  EXPECT_EQ(At(0, 4500), 1500);
  EXPECT_EQ(At(0, 4700), 1500);
  // Dual slope: through (2030h, 3040h).
  EXPECT_EQ(At(1, 1400), 750);
  EXPECT_EQ(At(1, 950), 375);
  EXPECT_EQ(At(1, 2950), 1125);
}

TEST_F(AoProfileTest, DualProfileAUsesTheUpperHalf) {
  EXPECT_EQ(At(2, 2600), 0);  // below the deadband maximum: off
  EXPECT_EQ(At(2, 2700), 0);  // the minimum current at 2050h
  EXPECT_EQ(At(2, 3600), 750);
  EXPECT_EQ(At(2, 4500), 1500);
  EXPECT_EQ(At(3, 3600), 750);  // dual slope through (2060h, 3040h)
  EXPECT_EQ(At(3, 3150), 375);
  EXPECT_EQ(At(3, 4050), 1125);
}

TEST_F(AoProfileTest, DualProfileBUsesTheLowerHalfFallingInput) {
  EXPECT_EQ(At(4, 2400), 0);  // above the deadband minimum: off
  EXPECT_EQ(At(4, 2300), 0);
  EXPECT_EQ(At(4, 1400), 750);
  EXPECT_EQ(At(4, 500), 1500);
  EXPECT_EQ(At(4, 300), 1500);
  EXPECT_EQ(At(5, 1400), 750);  // dual slope through (2030h, 3040h)
  EXPECT_EQ(At(5, 1850), 375);
  EXPECT_EQ(At(5, 950), 1125);
  EXPECT_EQ(At(6, 1000), 0);  // not a profile
}

}  // namespace
}  // namespace canfleet::devices::test
