#include "tests/system/fleet/fleet_harness.hpp"

#include <google/protobuf/util/json_util.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace canfleet::system_test {

namespace {

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

CliResult RunCanfleet(const std::vector<std::string>& args) {
  static int counter = 0;
  TempDir dir;
  const std::string err_path = dir.File("stderr" + std::to_string(++counter));
  std::vector<std::string> argv{PROGRAM_CANFLEET};
  argv.insert(argv.end(), args.begin(), args.end());
  ChildProcess child(argv, err_path);
  // Read stdout to its end (the child closes it when it exits).
  child.WaitForLine([](const std::string&) { return false; }, std::chrono::seconds(60));
  CliResult result;
  result.exit_code = child.Wait(std::chrono::seconds(60)).value_or(-1);
  for (const auto& line : child.Lines())
    result.out += line + "\n";
  result.err = child.Log();
  return result;
}

bool ParseJson(const std::string& json, google::protobuf::Message& message, std::string* error) {
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = true;
  const auto status = google::protobuf::util::JsonStringToMessage(json, &message, options);
  if (!status.ok() && error) *error = std::string(status.message()) + " in: " + json;
  return status.ok();
}

FleetUnderTest::FleetUnderTest(const std::string& topology, const std::string& listen,
                               const std::vector<std::string>& up_args) {
  // The fleet's nodes publish telemetry; keep it off other tests' DDS domain.
  ::setenv("CANFLEET_DDS_DOMAIN", "76", 0);
  const std::string file = dir_.File("fleet.textproto");
  std::ofstream(file) << topology;
  std::vector<std::string> argv = {PROGRAM_CANFLEET,
                                   "up",
                                   file,
                                   "--control",
                                   "tcp://127.0.0.1:0",
                                   "--listen",
                                   listen,
                                   "--ready-file",
                                   dir_.File("ready"),
                                   "--node-binary",
                                   PROGRAM_CANFLEET_NODE,
                                   "--log-level",
                                   "debug"};
  argv.insert(argv.end(), up_args.begin(), up_args.end());
  up_ = std::make_unique<ChildProcess>(argv, dir_.File("orchestrator.log"));
  WaitUntil(
      [&] {
        const std::string ready = ReadFile(dir_.File("ready"));
        const auto at = ready.find("control ");
        if (at == std::string::npos) return false;
        control_ = ready.substr(at + 8, ready.find('\n', at) - at - 8);
        return true;
      },
      std::chrono::seconds(30));
}

FleetUnderTest::~FleetUnderTest() {
  const auto pids = NodePids();
  up_->Signal(SIGTERM);
  up_->Wait(std::chrono::seconds(30));
  // No orphans: every node process the orchestrator reported is gone.
  for (const int pid : pids) {
    if (!WaitUntil([pid] { return ::kill(pid, 0) != 0; }, std::chrono::seconds(10)))
      ADD_FAILURE() << "node process " << pid << " outlived its orchestrator";
  }
}

bool FleetUnderTest::WaitReady(std::chrono::milliseconds timeout) {
  return WaitUntil([&] { return ReadFile(dir_.File("ready")).find("state ready") != std::string::npos; },
                   timeout);
}

CliResult FleetUnderTest::Cli(std::vector<std::string> args) const {
  args.insert(args.begin(), {"--control", control_});
  return RunCanfleet(args);
}

control::Status FleetUnderTest::Status() const {
  control::Status status;
  const auto result = Cli({"status", "--json"});
  ParseJson(result.out, status);
  return status;
}

const control::NodeStatus* FleetUnderTest::Node(const control::Status& status,
                                                const std::string& name) const {
  for (const auto& node : status.nodes())
    if (node.name() == name) return &node;
  // An empty status (the orchestrator did not answer) reads as a node with nothing known, so a
  // polling condition stays false instead of crashing the test.
  static const control::NodeStatus unknown;
  return &unknown;
}

std::optional<std::uint64_t> FleetUnderTest::SdoReadUnsigned(const std::string& node,
                                                             const std::string& index, int sub,
                                                             const std::string& type,
                                                             std::string* error) const {
  const auto result = Cli({"sdo", "read", node, index, std::to_string(sub), type, "--json"});
  if (result.exit_code != 0) {
    if (error) *error = result.err;
    return std::nullopt;
  }
  control::SdoData data;
  if (!ParseJson(result.out, data, error)) return std::nullopt;
  std::uint64_t value = 0;
  for (std::size_t i = data.data().size(); i-- > 0;)
    value = (value << 8) | static_cast<std::uint8_t>(data.data()[i]);
  return value;
}

std::optional<std::string> FleetUnderTest::IoGet(const std::string& node, const std::string& name) const {
  const auto result = Cli({"io", "get", node, name, "--json"});
  if (result.exit_code != 0) return std::nullopt;
  control::IoValues values;
  if (!ParseJson(result.out, values)) return std::nullopt;
  for (const auto& v : values.values())
    if (v.name() == name) return v.value();
  return std::nullopt;
}

std::string FleetUnderTest::Log() const {
  up_->Poll();  // the orchestrator logs on stdout
  std::string log;
  for (const auto& line : up_->Lines())
    log += line + "\n";
  return log + ReadFile(dir_.File("orchestrator.log"));
}

std::string FleetUnderTest::NodeLog(const std::string& name) const {
  return ReadFile(dir_.File(".canfleet/fleet-test/logs/" + name + ".log"));
}

std::vector<int> FleetUnderTest::NodePids() const {
  std::vector<int> pids;
  const auto status = Status();
  for (const auto& node : status.nodes())
    if (node.pid() > 0) pids.push_back(node.pid());
  return pids;
}

}  // namespace canfleet::system_test
