// NMT behaviour of the Quad (AX020506 §3.1.10, §4.2): boot into pre-operational, 5555h "Start in
// Operational Mode" (stored with 1010h), no PDOs before operational, stopped.
#include <unistd.h>

#include "tests/unit/devices/quad_fixture.hpp"

namespace canfleet::devices::test {
namespace {

std::filesystem::path StateDir() {
  return std::filesystem::path(::testing::TempDir()) /
         ("canfleet-quad-" + std::to_string(::getpid()) + "-" +
          ::testing::UnitTest::GetInstance()->current_test_info()->name());
}

class QuadNmtTest : public QuadTest {
 protected:
  QuadNmtTest() : QuadTest(Prepare()) {}
  ~QuadNmtTest() override { std::filesystem::remove_all(StateDir()); }
  static std::filesystem::path Prepare() {
    std::filesystem::remove_all(StateDir());
    return StateDir();
  }
};

// §4.2 / CiA 301: boot-up into pre-operational (the fixture saw "705#00"); no PDO before
// operational even though TPDO1-4 have 100 ms event timers.
TEST_F(QuadNmtTest, BootsIntoPreOperationalWithoutPdos) {
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
  Advance(500ms);
  EXPECT_TRUE(Frames().empty());
  Start();
  Advance(99ms);
  EXPECT_EQ(Frames().size(), 4u);
}

// §3.1.10: 5555h TRUE → the node starts in operational by itself; 1010h sub 4 "save" (§3.1.5)
// keeps it over a reset.
TEST_F(QuadNmtTest, StartInOperationalModeIsStoredAndBootsOperational) {
  Write(0x5555, 0, 1, 1);
  Write(0x1010, 4, 0x65766173, 4);
  Send("000#8105");  // reset node
  EXPECT_EQ(Frames(), std::vector<std::string>{"705#00"});
  EXPECT_EQ(stack().State(), canopen::NmtState::kOperational);
  Advance(100ms);
  EXPECT_EQ(Frames("185#").size(), 1u);
  // 1011h "load" (§3.1.6): defaults again after the next reset.
  Write(0x1011, 1, 0x64616F6C, 4);
  Send("000#8105");
  EXPECT_EQ(stack().State(), canopen::NmtState::kPreOperational);
}

// §3.1.5: "save" stores parameters, not the process data that drives outputs: after a reset
// 7330h and 6200h are back at 0 while a saved parameter (3080h) is kept.
TEST_F(QuadNmtTest, SavingDoesNotStoreOutputCommands) {
  Start();
  Write(0x7330, 1, 1000, 2);
  Write(0x6200, 1, 0x10, 1);
  Write(0x3080, 1, 800, 2);
  Write(0x1010, 1, 0x65766173, 4);
  Send("000#8105");
  Start();
  EXPECT_EQ(Read(0x7330, 1), 0);
  EXPECT_EQ(Read(0x6200, 1), 0);
  EXPECT_EQ(Read(0x3080, 1), 800);
  EXPECT_EQ(io().Number("OUT1.current_mA"), 0);
  EXPECT_FALSE(io().Bool("OUT5.on"));
}

// §4.2 "Stopped Behaviour": only NMT and error control; no SDO, no outputs.
TEST_F(QuadNmtTest, StoppedAnswersNoSdo) {
  Send("000#0205");
  EXPECT_EQ(Sdo(SdoRead(0x1000, 0)), "");
  Send("000#8005");
  EXPECT_EQ(Sdo(SdoRead(0x1000, 0)), "585#4300100094010F00");
}

}  // namespace
}  // namespace canfleet::devices::test
