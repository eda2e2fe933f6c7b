// What `canfleet test` prints and writes (issue 21): result and summary lines, and JUnit XML with
// one suite per file, one case per expectation, the failure naming what was seen and when.
#include "orchestrator/scenario/report.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>

namespace canfleet::scenario {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

FileReport Example() {
  FileReport f;
  f.file = "topologies/scenarios/x.textproto";
  f.topology = "x";
  f.seconds = 9.5;
  Result pass{1,
              "emcy",
              "EMCY 8130h from quad-6 within 1500 ms after cut-hb",
              {Outcome::kPassed, TimePoint{} + 5412ms, "seen EMCY 8130h at t=5.412 s"},
              TimePoint{} + 5s};
  Result fail{2,
              "preop",
              "quad-6 pre-operational within 500 ms after emcy",
              {Outcome::kFailed, TimePoint{} + 5912ms, "was operational at t=5.900 s & <later>"},
              TimePoint{} + 5412ms};
  f.results = {pass, fail};
  f.lines = {12, 14};
  return f;
}

TEST(ReportTest, ResultAndSummaryLines) {
  const FileReport f = Example();
  EXPECT_EQ(
      ResultLine(f.file, 12, f.results[0]),
      "pass  topologies/scenarios/x.textproto:12  emcy: EMCY 8130h from quad-6 within 1500 ms after cut-hb: "
      "seen EMCY 8130h at t=5.412 s");
  Totals t;
  t.Add(f);
  EXPECT_FALSE(t.AllPassed());
  EXPECT_EQ(
      SummaryLine(t, 1, 9.5),
      "canfleet test: FAILED, 1 passed, 1 failed, 0 skipped, 0 errors (2 expectations in 1 file, 9.5 s)");
}

TEST(ReportTest, JunitHasASuitePerFileACasePerExpectationAndEscapes) {
  JunitRun run;
  run.files = {Example()};
  run.seed = 7;
  std::ostringstream xml;
  WriteJunit(xml, run);
  const std::string s = xml.str();
  EXPECT_THAT(s, HasSubstr("<testsuites name=\"canfleet test\" tests=\"2\" failures=\"1\" errors=\"0\""));
  EXPECT_THAT(s, HasSubstr("<testsuite name=\"x\" file=\"topologies/scenarios/x.textproto\" tests=\"2\""));
  EXPECT_THAT(s, HasSubstr("<property name=\"seed\" value=\"7\"/>"));
  EXPECT_THAT(s, HasSubstr("line=\"14\" time=\"0.500\""));
  EXPECT_THAT(s, HasSubstr("<failure message=\"was operational at t=5.900 s &amp; &lt;later&gt;\""));
}

TEST(ReportTest, AFleetThatDidNotStartIsAnError) {
  FileReport f = Example();
  f.error = "node quad-6 exited before the fleet was ready";
  for (auto& r : f.results)
    r.verdict = {Outcome::kSkipped, {}, ""};
  Totals t;
  t.Add(f);
  EXPECT_EQ(t.errors, 1u);
  EXPECT_FALSE(t.AllPassed());
  std::ostringstream xml;
  WriteJunit(xml, {{f}, std::nullopt, "real"});
  EXPECT_THAT(xml.str(), HasSubstr("<error message=\"node quad-6 exited before the fleet was ready\""));
  EXPECT_THAT(xml.str(), HasSubstr("<skipped message=\"node quad-6 exited before the fleet was ready\"/>"));
}

}  // namespace
}  // namespace canfleet::scenario
