#pragma once
/// @file A fleet under test: `canfleet up` as a real child process on a topology written by the
/// test, driven through the real `canfleet` CLI (its --json output parsed back into the control
/// API's messages). Ports are picked by the kernel (tcp://127.0.0.1:0) and read from --ready-file.

#include <google/protobuf/message.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "orchestrator/control/canfleet_control.pb.h"
#include "tests/system/support/child_process.hpp"

namespace canfleet::system_test {

struct CliResult {
  int exit_code = -1;
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};

/// Runs `canfleet ARGS...` to completion (generous timeout).
CliResult RunCanfleet(const std::vector<std::string>& args);

class FleetUnderTest {
 public:
  /// Writes `topology` (text format) as DIR/fleet.textproto and starts `canfleet up` on it, its
  /// broker listening on `listen` (default: a port the kernel picks), with `up_args` added to its
  /// command line.
  explicit FleetUnderTest(const std::string& topology, const std::string& listen = "tcp://127.0.0.1:0",
                          const std::vector<std::string>& up_args = {});
  /// SIGTERM to the orchestrator; waits for it; checks no node process is left.
  ~FleetUnderTest();

  /// Waits until the ready file says "state ready" (every node booted and configured).
  bool WaitReady(std::chrono::milliseconds timeout = std::chrono::seconds(60));
  const std::string& control() const { return control_; }

  /// `canfleet --control EP ARGS...`
  CliResult Cli(std::vector<std::string> args) const;
  /// `canfleet status --json` parsed.
  control::Status Status() const;
  /// Never null: an unknown name gives an empty NodeStatus.
  const control::NodeStatus* Node(const control::Status& status, const std::string& name) const;
  /// `canfleet sdo read NODE INDEX SUB u32 --json` → the value, or nullopt with the error in `error`.
  std::optional<std::uint64_t> SdoReadUnsigned(const std::string& node, const std::string& index, int sub,
                                               const std::string& type, std::string* error = nullptr) const;
  /// `canfleet io get NODE NAME --json` → the value text.
  std::optional<std::string> IoGet(const std::string& node, const std::string& name) const;

  /// The orchestrator's log so far, and a node's log file.
  std::string Log() const;
  std::string NodeLog(const std::string& name) const;
  ChildProcess& process() { return *up_; }
  const TempDir& dir() const { return dir_; }
  std::vector<int> NodePids() const;

 private:
  TempDir dir_;
  std::unique_ptr<ChildProcess> up_;
  std::string control_;
};

/// Parses --json output into `message`; false (with the reason in `error`) when it is not.
bool ParseJson(const std::string& json, google::protobuf::Message& message, std::string* error = nullptr);

}  // namespace canfleet::system_test
