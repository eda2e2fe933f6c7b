// The Quad's digital input block (AX020506 §2.2, §3.2): digital mode with hardware level and
// software polarity, ON/OFF mode with thresholds, 6000h and its TPDO.
#include "tests/unit/devices/quad_fixture.hpp"

namespace canfleet::devices::test {
namespace {

class QuadDiTest : public QuadTest {
 protected:
  std::int64_t ReadState() { return Read(0x6000, 1); }
};

// §3.2.1: 2000h bit 1 = active high (pull-down: on when switched to +V), 0 = active low (pull-up:
// on when switched to ground); a floating pin is off either way.
TEST_F(QuadDiTest, DigitalModeFollowsTheActiveLevel) {
  Write(0x6112, 1, 10, 1);
  Write(0x6112, 2, 10, 1);
  Write(0x2000, 1, 0x3D, 1);  // DIN2 active low, the others active high
  Advance(10ms);
  EXPECT_EQ(ReadState(), 0);
  SetEnum("IN1.level", "high");
  SetEnum("IN2.level", "low");
  Advance(10ms);
  EXPECT_EQ(ReadState(), 0x03);
  SetEnum("IN1.level", "low");
  SetEnum("IN2.level", "high");
  Advance(10ms);
  EXPECT_EQ(ReadState(), 0);
}

// §3.2.5: 6002h inverts a digital input.
TEST_F(QuadDiTest, PolarityInvertsDigitalInputs) {
  Write(0x6112, 6, 10, 1);
  Write(0x6002, 1, 0x20, 1);
  Advance(10ms);
  EXPECT_EQ(ReadState(), 0x20);  // floating, inverted: on
  SetEnum("IN6.level", "high");
  Advance(10ms);
  EXPECT_EQ(ReadState(), 0);
}

// §2.2: ≤ 2001h → OFF, ≥ 2002h → ON, in between the state holds; 6002h is ignored.
TEST_F(QuadDiTest, OnOffModeHasHysteresisAndIgnoresPolarity) {
  Write(0x6112, 3, 20, 1);
  Write(0x6002, 1, 0x04, 1);
  SetNumber("IN3.voltage_mV", 3600);
  Advance(10ms);
  EXPECT_EQ(ReadState(), 0x04);
  SetNumber("IN3.voltage_mV", 2000);
  Advance(10ms);
  EXPECT_EQ(ReadState(), 0x04);
  SetNumber("IN3.voltage_mV", 1500);
  Advance(10ms);
  EXPECT_EQ(ReadState(), 0);
  SetNumber("IN3.voltage_mV", 3400);
  Advance(10ms);
  EXPECT_EQ(ReadState(), 0);
  // Thresholds are in the field value units of the input: 0.01 % for a PWM FIN.
  Write(0x6112, 5, 20, 1);
  SetNumber("IN5.duty_pct", 80);
  Advance(10ms);
  EXPECT_EQ(ReadState(), 0x10);
}

// §3.2.4: inputs not in digital or ON/OFF mode read 0, whatever the pin.
TEST_F(QuadDiTest, OtherModesReadZero) {
  SetEnum("IN1.level", "high");
  SetNumber("IN1.voltage_mV", 4000);
  Advance(10ms);
  EXPECT_EQ(ReadState(), 0);
}

// §3.1.1: 6000h is mapped into TPDO3 (type 254): a change is sent at once in operational.
TEST_F(QuadDiTest, AChangeOfStateSendsTpdo3) {
  Start();
  SilenceTpdoTimers();
  Write(0x6112, 1, 10, 1);
  Advance(10ms);
  EXPECT_TRUE(Frames("385#").empty());
  SetEnum("IN1.level", "high");
  Advance(10ms);
  EXPECT_EQ(Frames(), std::vector<std::string>{"385#0100"});
  Advance(50ms);
  EXPECT_TRUE(Frames().empty());
}

}  // namespace
}  // namespace canfleet::devices::test
