// Start-up modes of the AX023241 (1.5 "Startup", C3-1.4.70 5555h, C3-1.4.71 5556h): pre-operational
// by default, operational by itself (1), and operational plus an NMT Start for every node after
// 5556h ms (2), sent from the device's own port.
#include "tests/unit/encoder/encoder_fixture.hpp"

namespace canfleet::devices::encoder::test {
namespace {

class StartupTest : public EncoderTest {
 protected:
  /// 5555h = mode, then NMT reset communication (which keeps 2000h-FFFFh): the node boots again.
  void BootWithMode(std::uint8_t mode) {
    Write(0x5555, 0, mode, 1);
    Frames();
    Send("000#8205");
  }
};

// 1.5: "By default, this object is disabled (FALSE)": the node waits in pre-operational.
TEST_F(StartupTest, DefaultWaitsInPreOperational) {
  EXPECT_EQ(Read(0x5555, 0), 0);
  EXPECT_EQ(Read(0x5556, 0), 1000);
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
  Advance(3000ms);
  EXPECT_TRUE(Frames("000#").empty());
}

// 5555h = 1: "Start directly in operational mode"; no NMT frame of its own.
TEST_F(StartupTest, ModeOneStartsOperational) {
  BootWithMode(1);
  EXPECT_EQ(Frames("705#"), std::vector<std::string>{"705#00"});
  EXPECT_EQ(stack().State(), canopen::NmtState::kOperational);
  Advance(3000ms);
  EXPECT_TRUE(Frames("000#").empty());
}

// 5555h = 2: operational at boot, and 5556h ms later NMT Start (01h) to all nodes (00h).
TEST_F(StartupTest, ModeTwoSendsNmtStartAfterTheDelay) {
  BootWithMode(2);
  EXPECT_EQ(stack().State(), canopen::NmtState::kOperational);
  Advance(999ms);
  EXPECT_TRUE(Frames("000#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("000#"), std::vector<std::string>{"000#0100"});
  Advance(5000ms);
  EXPECT_TRUE(Frames("000#").empty());  // once per boot
}

// 5556h sets the delay; a reset during it starts it over (one NMT Start per boot).
TEST_F(StartupTest, DelayIsConfigurableAndARebootStartsItOver) {
  Write(0x5556, 0, 250, 2);
  BootWithMode(2);
  Advance(200ms);
  Send("000#8205");
  Advance(249ms);
  EXPECT_TRUE(Frames("000#").empty());
  Advance(1ms);
  EXPECT_EQ(Frames("000#"), std::vector<std::string>{"000#0100"});
}

// 5555h = 3 is in the printed range 0-3 without a meaning: it behaves as 0 (README.md).
TEST_F(StartupTest, ModeThreeBehavesAsZero) {
  BootWithMode(3);
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
  EXPECT_EQ(TryWrite(0x5555, 0, 4, 1), SdoAborted(0x5555, 0, 0x06090031));
}

// A reset node restores 5555h to its default (nothing stored): the node waits again.
TEST_F(StartupTest, ResetNodeRestoresTheDefault) {
  BootWithMode(1);
  ASSERT_EQ(stack().State(), canopen::NmtState::kOperational);
  Send("000#8105");
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
  EXPECT_EQ(Read(0x5555, 0), 0);
}

}  // namespace
}  // namespace canfleet::devices::encoder::test
