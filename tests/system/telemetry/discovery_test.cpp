// Issue 7, memory per node: programs that only write telemetry announce themselves to the monitors
// and meet no other writer (telemetry/dds.hpp, DdsDiscovery::kMonitorsOnly), so a node of an
// N-node fleet keeps no DDS state for the N-1 others (about 30 kB of RSS each).
//
// Three canfleet-fake-fleet processes (writers, as canfleet-node) and a monitor in the test, on
// the loopback configuration with Cyclone's discovery trace switched on: each writer's trace must
// name exactly one discovered participant, the monitor, while the monitor sees all three. With
// --dds-discover-all (Cyclone's default behaviour) each writer meets the other two as well, which
// shows the trace is a faithful witness.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/system/support/child_process.hpp"
#include "tests/system/telemetry/dds_monitor.hpp"

namespace canfleet::system_test {
namespace {

using namespace std::chrono_literals;

constexpr int kWriters = 3;

/// The loopback configuration plus Cyclone's discovery trace, one file per process: the trace's
/// name comes from CANFLEET_TEST_TRACE, which the test sets before starting each process.
std::string TracingConfig(const TempDir& dir) {
  std::ifstream loopback(CANFLEET_DDS_LOOPBACK_CONFIG);
  std::stringstream text;
  text << loopback.rdbuf();
  std::string config = text.str();
  const std::string tracing = "<Tracing><Category>discovery</Category><OutputFile>" + dir.path() +
                              "/trace-${CANFLEET_TEST_TRACE}.log</OutputFile></Tracing>\n  </Domain>";
  const auto end = config.rfind("</Domain>");
  config.replace(end, std::string("</Domain>").size(), tracing);
  const std::string path = dir.File("cyclonedds-traced.xml");
  std::ofstream(path) << config;
  return path;
}

/// Remote participants a process discovered: its trace's "SPDP ST0 <guid> ... NEW" lines, as
/// "<process name> <pid>" from each one's properties.
std::vector<std::string> Discovered(const std::string& trace_file) {
  std::ifstream in(trace_file);
  const std::regex spdp_new(R"re(SPDP ST0 \S+ .* NEW .*"__ProcessName":"([^"]+)",1:"__Pid":"(\d+)")re");
  std::vector<std::string> found;
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_search(line, m, spdp_new)) found.push_back(m[1].str() + " " + m[2].str());
  }
  return found;
}

class DdsDiscoveryTest : public ::testing::TestWithParam<bool> {};

TEST_P(DdsDiscoveryTest, WritersMeetTheMonitorAndOnlyWithDiscoverAllEachOther) {
  const bool discover_all = GetParam();
  const std::uint32_t domain = discover_all ? 81 : 80;  // no other test publishes here
  TempDir dir;
  const std::string config = TracingConfig(dir);
  ::setenv("CANFLEET_TEST_TRACE", "monitor", 1);
  Monitor monitor(domain, config);
  std::vector<std::unique_ptr<ChildProcess>> writers;
  for (int i = 1; i <= kWriters; ++i) {
    ::setenv("CANFLEET_TEST_TRACE", ("writer-" + std::to_string(i)).c_str(), 1);  // inherited
    std::vector<std::string> argv = {PROGRAM_CANFLEET_FAKE_FLEET,
                                     "--dds-domain",
                                     std::to_string(domain),
                                     "--dds-config",
                                     config,
                                     "--nodes",
                                     "1",
                                     "--first-node",
                                     std::to_string(i)};
    if (discover_all) argv.push_back("--dds-discover-all");
    writers.push_back(std::make_unique<ChildProcess>(argv, dir.File("writer-" + std::to_string(i) + ".err")));
  }
  ::unsetenv("CANFLEET_TEST_TRACE");
  ASSERT_TRUE(monitor.Until([&] { return monitor.view().nodes().size() == kWriters; }, 30s))
      << monitor.view().nodes().size() << " of " << kWriters << " nodes seen";
  // Writers that discover each other do so within a second or two of starting; give them more.
  std::this_thread::sleep_for(3s);

  const std::string self = " " + std::to_string(::getpid());
  for (int i = 1; i <= kWriters; ++i) {
    const auto found = Discovered(dir.File("trace-writer-" + std::to_string(i) + ".log"));
    const auto monitors =
        std::count_if(found.begin(), found.end(), [&](const std::string& p) { return p.ends_with(self); });
    const auto writers_met = std::count_if(
        found.begin(), found.end(), [](const std::string& p) { return p.starts_with("canfleet-fake"); });
    std::string all;
    for (const auto& p : found)
      all += "\n  " + p;
    EXPECT_EQ(monitors, 1) << "writer " << i << " discovered:" << all;
    EXPECT_EQ(writers_met, discover_all ? kWriters - 1 : 0) << "writer " << i << " discovered:" << all;
  }
  // The monitor, which discovers everyone, met all three writers.
  const auto monitor_found = Discovered(dir.File("trace-monitor.log"));
  EXPECT_EQ(std::count_if(monitor_found.begin(), monitor_found.end(),
                          [](const std::string& p) { return p.starts_with("canfleet-fake"); }),
            kWriters);
}

INSTANTIATE_TEST_SUITE_P(Writers, DdsDiscoveryTest, ::testing::Values(false, true),
                         [](const auto& param_info) {
                           return param_info.param ? "DiscoverAll" : "MonitorsOnly";
                         });

}  // namespace
}  // namespace canfleet::system_test
