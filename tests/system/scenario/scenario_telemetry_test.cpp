// Issue 29: a scenario's verdicts and clock reach DDS. `canfleet up` runs a topology whose scenario
// has an expectation that passes and one written to fail; a reader in the test receives a Verdict
// per expectation with the very line the orchestrator's log prints, and the ScenarioStatus with
// the counts; `canfleet top --once` (a late joiner) shows the scenario line, the verdicts and the
// nodes' topology names within 80 columns; `canfleet watch --type verdict --json` prints them.
#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>

#include "tests/support/text_lines.hpp"
#include "tests/system/fleet/fleet_harness.hpp"
#include "tests/system/telemetry/dds_monitor.hpp"

namespace canfleet::system_test {
namespace {

using namespace std::chrono_literals;
using tools::EventKind;
using tools::FleetEvent;

constexpr std::uint32_t kDomain = 46;  // no other test publishes here
constexpr auto kPatience = 90s;

/// quad-6's output follows quad-5's AIN1 through RPDO1 (as the scenario library's heartbeat-loss
/// file wires it); "steady" passes, "wrong-current" asks for a current it never drives and fails.
/// The scenario repeats only after 10 minutes: its status stays, done, while the test reads it.
std::string Topology() {
  return R"(name: "verdicts"
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0"
       io { key: "IN1.voltage_mV" value: "1200" }
       heartbeat { producer_ms: 200 } }
node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
       heartbeat { producer_ms: 200 consumer { node: "quad-5" timeout_ms: 1000 } }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x80000185" }
       sdo { index: 0x1400 subindex: 1 type: "u32" value: "0x185" } }
scenario_repeat_ms: 600000
scenario { name: "steady" expect { within_ms: 3000 nmt { node: "quad-6" state: "operational" } } }
scenario { name: "wrong-current" expect { within_ms: 1500 throughout: true
  io { node: "quad-6" name: "OUT1.current_mA" min: 4000 max: 5000 } } }
)";
}

/// The fleet's processes publish on kDomain with the loopback configuration (inherited by
/// `canfleet up`, its nodes and the tools the test runs).
std::string UseTestDomain() {
  ::setenv("CANFLEET_DDS_DOMAIN", std::to_string(kDomain).c_str(), 1);
  ::setenv("CANFLEET_DDS_CONFIG", CANFLEET_DDS_LOOPBACK_CONFIG, 1);
  return Topology();
}

const FleetEvent* FindVerdict(const Monitor& monitor, const std::string& name) {
  for (const auto& e : monitor.events())
    if (e.kind == EventKind::kVerdict && e.verdict && e.verdict->name == name) return &e;
  return nullptr;
}

using ::canfleet::test::Lines;

TEST(ScenarioTelemetry, VerdictsAndTheScenarioClockReachDdsTopAndWatch) {
  FleetUnderTest fleet{UseTestDomain()};
  Monitor monitor(kDomain, CANFLEET_DDS_LOOPBACK_CONFIG);
  ASSERT_TRUE(fleet.WaitReady(kPatience)) << fleet.Log();

  ASSERT_TRUE(monitor.Until(
      [&] { return FindVerdict(monitor, "steady") && FindVerdict(monitor, "wrong-current"); }, kPatience))
      << fleet.Log();
  const auto& steady = *FindVerdict(monitor, "steady")->verdict;
  const auto& wrong = *FindVerdict(monitor, "wrong-current")->verdict;
  const std::string file = fleet.dir().File("fleet.textproto");
  EXPECT_EQ(steady.source, file);
  EXPECT_EQ(steady.scenario, "verdicts");
  EXPECT_EQ(steady.cycle, 1u);
  EXPECT_EQ(steady.index, 0);
  EXPECT_EQ(steady.line, 11u);
  EXPECT_EQ(steady.result, telemetry::VerdictResult::kPass);
  EXPECT_EQ(steady.text.rfind("pass  " + file +
                                  ":11  steady: quad-6 operational within 3000 ms after the start: "
                                  "operational",
                              0),
            0u)
      << steady.text;
  EXPECT_FALSE(steady.text_cut);
  EXPECT_GE(steady.scenario_time_s, 0.0);
  EXPECT_EQ(wrong.index, 1);
  EXPECT_EQ(wrong.result, telemetry::VerdictResult::kFail);
  EXPECT_EQ(wrong.text.rfind("FAIL  " + file + ":12  wrong-current: ", 0), 0u) << wrong.text;
  // The same line as the orchestrator's log (and `canfleet test`) prints.
  EXPECT_NE(fleet.Log().find("expect " + steady.text), std::string::npos) << fleet.Log();
  EXPECT_NE(fleet.Log().find("expect " + wrong.text), std::string::npos) << fleet.Log();

  // The scenario's status: both decided, done; the clock goes on.
  ASSERT_TRUE(monitor.Until(
      [&] {
        const auto it = monitor.view().scenarios().find(file);
        return it != monitor.view().scenarios().end() && it->second.status.passed == 1 &&
               it->second.status.failed == 1 && it->second.status.pending == 0 && !it->second.status.running;
      },
      kPatience));
  const auto& status = monitor.view().scenarios().at(file).status;
  EXPECT_EQ(status.scenario, "verdicts");
  EXPECT_EQ(status.time_mode, "real");
  EXPECT_EQ(status.cycle, 1u);
  EXPECT_EQ(status.expectations, 2);
  EXPECT_EQ(status.step, "wrong-current");
  EXPECT_GT(status.scenario_time_s, 0.0);

  // The nodes' topology names travel in NodeStatus.
  ASSERT_TRUE(monitor.Until([&] { return monitor.Node("can0", 6) != nullptr; }, kPatience));
  EXPECT_EQ(monitor.Node("can0", 6)->status.name, "quad-6");

  // `canfleet top --once`, a late joiner, at 80 columns.
  const CliResult top = RunCanfleet({"top", "--once", "--width", "80", "--color", "never", "--wait", "30"});
  ASSERT_EQ(top.exit_code, 0) << top.err;
  const auto lines = Lines(top.out);
  for (const auto& line : lines)
    EXPECT_LE(line.size(), 80u) << line;
  const auto scenario = std::find_if(
      lines.begin(), lines.end(), [](const std::string& l) { return l.rfind("scenario verdicts", 0) == 0; });
  ASSERT_NE(scenario, lines.end()) << top.out;
  EXPECT_NE(scenario->find("1 passed  1 FAILED  0 pending"), std::string::npos) << *scenario;
  EXPECT_NE(top.out.find("\n  quad-5 "), std::string::npos) << top.out;
  EXPECT_NE(top.out.find("\n  quad-6 "), std::string::npos) << top.out;
  EXPECT_NE(top.out.find(" operational "), std::string::npos) << top.out;
  EXPECT_NE(top.out.find("FAIL wrong-current (cycle 1): "), std::string::npos) << top.out;

  // `canfleet watch`: verdicts as JSON lines, the whole result line in "text".
  const CliResult watch =
      RunCanfleet({"watch", "--json", "--history", "--type", "verdict", "--count", "2", "--timeout", "30"});
  ASSERT_EQ(watch.exit_code, 0) << watch.err;
  EXPECT_NE(watch.out.find(R"("type":"verdict")"), std::string::npos) << watch.out;
  EXPECT_NE(watch.out.find(R"("result":"FAIL","name":"wrong-current","line":12,)"), std::string::npos)
      << watch.out;
  EXPECT_NE(watch.out.find(R"("result":"pass","name":"steady","line":11,)"), std::string::npos) << watch.out;
}

}  // namespace
}  // namespace canfleet::system_test
