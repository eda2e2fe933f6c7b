// `canfleet test` end to end (issue 21): a real fleet (canfleet-node processes) runs a scenario
// whose EMCY expectation is wrong on purpose (8131h where the Quad's manual, §4.1, says 8130h for
// a lost heartbeat). The failure line names the EMCY seen instead and when, the JUnit report
// has the failure, the other expectations pass, and the exit code is 1. A file with a typo is
// refused with file, line and field before anything starts.
#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <fstream>
#include <sstream>

#include "tests/system/support/child_process.hpp"

namespace canfleet::system_test {
namespace {

constexpr const char* kWrongEmcy = R"(
name: "wrong-emcy"
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0" heartbeat { producer_ms: 200 } }
node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
       heartbeat { producer_ms: 200 consumer { node: "quad-5" timeout_ms: 1000 } } }
scenario { at_ms: 1500 name: "cut-hb" inject { kind: HEARTBEAT_LOSS node: "quad-5" } }
scenario { name: "wrong" expect { after: "cut-hb" within_ms: 2500 emcy { node: "quad-6" code: 0x8131 } } }
scenario { name: "preop" expect { after: "cut-hb" within_ms: 4000 nmt { node: "quad-6" state: "pre-operational" } } }
)";

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string Joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& line : lines)
    out += line + "\n";
  return out;
}

TEST(CanfleetTestCommandTest, AWrongEmcyCodeFailsWithWhatWasSeenInTheLineAndTheJunitReport) {
  TempDir dir;
  const std::string file = dir.File("wrong-emcy.textproto");
  std::ofstream(file) << kWrongEmcy;
  const std::string junit = dir.File("report.xml");
  ChildProcess test({PROGRAM_CANFLEET, "test", file, "--junit", junit, "--seed", "7", "--state-dir",
                     dir.File("state"), "--node-binary", PROGRAM_CANFLEET_NODE},
                    dir.File("stderr.log"));
  // Every line up to the end of its output (the fleet runs in real time: a generous bound).
  test.WaitForLine([](const std::string&) { return false; }, std::chrono::seconds(120));
  const auto status = test.Wait(std::chrono::seconds(30));
  ASSERT_TRUE(status.has_value()) << Joined(test.Lines());
  const std::string out = Joined(test.Lines());
  EXPECT_EQ(*status, 1) << out << test.Log();
  // The failure line: the file and the step's line, what was expected, and what was seen instead.
  EXPECT_NE(out.find("FAIL  " + file +
                     ":8  wrong: EMCY 8131h from quad-6 within 2500 ms after cut-hb: saw EMCY "
                     "8130h (register 01h, data 05 08 00 00 00) at t="),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("pass  " + file + ":9  preop: quad-6 pre-operational"), std::string::npos) << out;
  EXPECT_NE(out.find("canfleet test: FAILED, 1 passed, 1 failed, 0 skipped, 0 errors"), std::string::npos)
      << out;

  const std::string xml = Read(junit);
  EXPECT_NE(xml.find("<testsuite name=\"wrong-emcy\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("<failure message=\"saw EMCY 8130h (register 01h, data 05 08 00 00 00) at t="),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find("<property name=\"seed\" value=\"7\"/>"), std::string::npos) << xml;
}

TEST(CanfleetTestCommandTest, ATypoInAnExpectationIsRefusedWithFileLineAndField) {
  TempDir dir;
  const std::string file = dir.File("typo.textproto");
  std::string text = kWrongEmcy;
  text.replace(text.find("state: \"pre-operational\""), 25, "state: \"preoperational\"");
  std::ofstream(file) << text;
  ChildProcess test({PROGRAM_CANFLEET, "test", file, "--node-binary", PROGRAM_CANFLEET_NODE},
                    dir.File("stderr.log"));
  test.WaitForLine([](const std::string&) { return false; }, std::chrono::seconds(60));
  const auto status = test.Wait(std::chrono::seconds(30));
  ASSERT_TRUE(status.has_value());
  const std::string out = Joined(test.Lines());
  EXPECT_EQ(*status, 2) << out;
  EXPECT_NE(out.find(file + ":9:"), std::string::npos) << out;
  EXPECT_NE(out.find("scenario[2].expect.nmt.state: \"preoperational\" is not a state"), std::string::npos)
      << out;
}

// `canfleet up` runs a scenario with scenario_repeat_ms again once it has ended: the same
// labelled fault is injected and cleared in every run (the last run cleared it, so the next can
// inject it again) and every run's expectations are judged and logged afresh.
constexpr const char* kRepeating = R"(
name: "repeating"
scenario_repeat_ms: 500
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0" heartbeat { producer_ms: 200 } }
node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
       heartbeat { producer_ms: 200 consumer { node: "quad-5" timeout_ms: 1000 } } }
scenario { at_ms: 300 name: "cut-hb" inject { kind: HEARTBEAT_LOSS node: "quad-5" label: "hb" } }
scenario { name: "emcy" expect { after: "cut-hb" within_ms: 4000 emcy { node: "quad-6" code: 0x8130 } } }
scenario { at_ms: 3000 clear { label: "hb" } }
scenario { at_ms: 3100 name: "start" nmt { action: NMT_START } }
scenario { expect { after: "start" within_ms: 4000 nmt { node: "quad-6" state: "operational" } } }
)";

std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
    ++n;
  return n;
}

TEST(CanfleetUpScenarioTest, ARepeatingScenarioRunsAgainAndInjectsItsFaultsAgain) {
  TempDir dir;
  const std::string file = dir.File("repeating.textproto");
  std::ofstream(file) << kRepeating;
  ChildProcess up({PROGRAM_CANFLEET, "up", file, "--control", "tcp://127.0.0.1:0", "--listen",
                   "tcp://127.0.0.1:0", "--node-binary", PROGRAM_CANFLEET_NODE},
                  dir.File("stderr.log"));
  // Two runs of about 4 s each on a real clock: a generous bound. The log is on stdout.
  const auto third_run = up.WaitForLine(
      [](const std::string& line) { return line.find("scenario run 3:") != std::string::npos; },
      std::chrono::seconds(90));
  // Runs 1 and 2: the lines before run 3 began (run 3 may already be judging).
  std::vector<std::string> lines = up.Lines();
  const auto run3 = std::find_if(lines.begin(), lines.end(), [](const std::string& line) {
    return line.find("scenario run 3:") != std::string::npos;
  });
  lines.erase(run3, lines.end());
  const std::string log = Joined(lines);
  up.Signal(SIGTERM);
  up.Wait(std::chrono::seconds(30));
  ASSERT_TRUE(third_run) << log << up.Log();
  EXPECT_NE(log.find("scenario run 2: 5 step(s), 2 expectation(s)"), std::string::npos) << log;
  // Each run judged completely, on its own.
  // The log's verdicts are the lines `canfleet test` prints: "expect pass  FILE:LINE  NAME: ...".
  EXPECT_EQ(Count(log, "expect pass  " + file + ":"), 4u) << log;
  EXPECT_EQ(Count(log, "  emcy: EMCY 8130h from quad-6"), 2u) << log;
  EXPECT_EQ(Count(log, "  scenario[4]: quad-6 operational"), 2u) << log;
  EXPECT_EQ(Count(log, "expect FAIL"), 0u) << log;
  EXPECT_EQ(Count(log, "expect skip"), 0u) << log;
  EXPECT_EQ(log.find("already active"), std::string::npos) << log;
}

}  // namespace
}  // namespace canfleet::system_test
