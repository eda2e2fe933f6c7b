// The system tests' child process harness itself (support/child_process.hpp).
#include "tests/system/support/child_process.hpp"

#include <gtest/gtest.h>

#include <chrono>

namespace canfleet::system_test {
namespace {

// A child that writes far more than a pipe holds (64 KiB) while the test does not look at its
// output must not block in write(): the reader thread drains it. Before it did, an orchestrator
// logging at debug level stopped answering the CLI this way (CI, stop 14). The child exits after
// writing; Wait's bound is generous, since a blocked child would never exit at all.
TEST(ChildProcess, AChildWritingMoreThanAPipeHoldsIsNeverBlockedByTheTest) {
  TempDir dir;
  ChildProcess child(
      {"/bin/sh", "-c", "i=0; while [ $i -lt 4000 ]; do printf '%0100d\\n' $i; i=$((i+1)); done; echo done"},
      dir.File("stderr"));
  ASSERT_EQ(child.Wait(std::chrono::seconds(60)), 0);  // 404 000 bytes written, none read by the test
  const auto lines = child.Lines();
  ASSERT_EQ(lines.size(), 4001u);
  EXPECT_EQ(lines.front(), std::string(100, '0'));
  EXPECT_EQ(lines.back(), "done");
}

TEST(ChildProcess, WaitForLineSeesLinesThatArrivedBeforeAndAfterTheCall) {
  TempDir dir;
  ChildProcess child({"/bin/sh", "-c", "echo first; read x; echo second $x"}, dir.File("stderr"));
  EXPECT_EQ(child.WaitForPrefix("first"), "first");
  child.WriteLine("go");
  EXPECT_EQ(child.WaitForPrefix("second"), "second go");
  EXPECT_EQ(child.WaitForPrefix("never", std::chrono::milliseconds(200)), std::nullopt);  // stdout closed
}

}  // namespace
}  // namespace canfleet::system_test
