// The digital input block (UMAX020411A §1.2, Tables 1 and 3, §3.3.2, §3.4.1-3.4.3): pin level,
// pull-up/down, polarity (normal, inverse, latched) into 6020h.
#include "tests/unit/valve/valve_fixture.hpp"

namespace canfleet::devices::valve::test {
namespace {

class ValveDiTest : public ValveTest {
 protected:
  void Level(std::string_view pin, std::string_view level) {
    SetEnum(pin, level);
    Advance(2ms);
  }
};

// Table 3, 0 (default): HIGH = ON, LOW or open = OFF. DI1 is sub-index 8.
TEST_F(ValveDiTest, NormalPolarity) {
  EXPECT_EQ(Read(0x6020, 8), 0);
  Level("IN8.level", "high");
  EXPECT_EQ(Read(0x6020, 8), 1);
  EXPECT_EQ(Read(0x7100, 8), 1);  // Table 10's digital row: the FV is the state
  Level("IN8.level", "low");
  EXPECT_EQ(Read(0x6020, 8), 0);
}

// Table 3, 1: HIGH = OFF, LOW or open = ON.
TEST_F(ValveDiTest, InversePolarity) {
  Write(0x2010, 9, 1, 1);
  Advance(2ms);
  EXPECT_EQ(Read(0x6020, 9), 1);  // DI2 open
  Level("IN9.level", "high");
  EXPECT_EQ(Read(0x6020, 9), 0);
}

// Table 1, 1: the 10 kOhm pull-up makes an open pin read HIGH.
TEST_F(ValveDiTest, PullUpMakesAnOpenPinHigh) {
  Write(0x2020, 10, 1, 1);
  Advance(2ms);
  EXPECT_EQ(Read(0x6020, 10), 1);
  Write(0x2020, 10, 2, 1);  // pull-down
  Advance(2ms);
  EXPECT_EQ(Read(0x6020, 10), 0);
}

// Table 3, 2: every LOW -> HIGH edge toggles the state; HIGH -> LOW changes nothing.
TEST_F(ValveDiTest, LatchedPolarity) {
  Write(0x2010, 11, 2, 1);
  Advance(2ms);
  EXPECT_EQ(Read(0x6020, 11), 0);
  Level("IN11.level", "high");
  EXPECT_EQ(Read(0x6020, 11), 1);
  Level("IN11.level", "low");
  EXPECT_EQ(Read(0x6020, 11), 1);
  Level("IN11.level", "high");
  EXPECT_EQ(Read(0x6020, 11), 0);
}

// §1.2: a universal input set to 6112h = 10 reads its pin as a digital input too.
TEST_F(ValveDiTest, UniversalInputAsDigital) {
  Write(0x6112, 3, 10, 1);
  Level("IN3.level", "high");
  EXPECT_EQ(Read(0x6020, 3), 1);
  EXPECT_EQ(Read(0x7100, 3), 1);
  EXPECT_EQ(Read(0x2102, 3), 0);  // Table 9: digital FV has no decimals (5550h cascade)
}

// Table 4, 0: a channel off reads 0 whatever its pin.
TEST_F(ValveDiTest, ChannelOff) {
  Level("IN12.level", "high");
  EXPECT_EQ(Read(0x6020, 12), 1);
  Write(0x6112, 12, 0, 1);
  Advance(2ms);
  EXPECT_EQ(Read(0x6020, 12), 0);
  EXPECT_EQ(Read(0x7100, 12), 0);
}

}  // namespace
}  // namespace canfleet::devices::valve::test
