#pragma once
/// @file What the node system tests share: a canfleet-broker process, canfleet-node processes
/// driven through --stdin-control, and the test's own master on the bus — a real BrokerClientPort
/// and SdoClient on an asio io_context in this process (never a mock), as any CANopen master
/// attached to the broker would be.

#include <asio/io_context.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bus/broker_client/broker_client_port.hpp"
#include "bus/can_frame.hpp"
#include "clock/asio_scheduler.hpp"
#include "node/canopen/od/abort_code.hpp"
#include "node/canopen/od/value.hpp"
#include "node/canopen/sdo/sdo_client.hpp"
#include "tests/system/support/child_process.hpp"

namespace canfleet::system_test {

/// A canfleet-broker process with one bus "can0" (500 kbit/s, paced), listening where asked
/// (port 0 = any); the bound endpoints come from its --ready-file.
class BrokerProcess {
 public:
  BrokerProcess(const TempDir& dir, const std::string& listen);
  ChildProcess& process() { return *process_; }
  /// The endpoint nodes connect to ("tcp://127.0.0.1:41234" or "unix:///tmp/...").
  const std::string& endpoint() const { return endpoint_; }
  std::string Log() const { return process_->Log(); }

 private:
  std::unique_ptr<ChildProcess> process_;
  std::string endpoint_;
};

/// A canfleet-node process with --stdin-control. Its stdout carries the control replies (and,
/// depending on the node's logger, its log lines); stderr goes to a file.
class NodeProcess {
 public:
  /// `args`: the command line after the program name.
  NodeProcess(const TempDir& dir, const std::string& tag, std::vector<std::string> args);

  ChildProcess& process() { return *process_; }

  /// `set NAME VALUE`: the reply ("ok" or "error: ..."), or "no reply".
  std::string Set(const std::string& name, const std::string& value);
  /// `get NAME`: the value text ("1200 mA"), or nullopt on an error or no reply.
  std::optional<std::string> Get(const std::string& name);
  /// `get NAME` as a number (the text up to the unit).
  std::optional<double> GetNumber(const std::string& name);

  /// Every log line the node wrote so far: stderr lines and stdout lines that are not control
  /// replies (spdlog lines start with '[').
  std::vector<std::string> LogLines();
  /// Every line the node wrote so far, stderr then stdout (all of them log lines as long as no
  /// control command was sent).
  std::vector<std::string> AllLines();
  /// Everything the node wrote so far, for failure messages.
  std::string Output();

 private:
  std::optional<std::string> Command(const std::string& line,
                                     const std::function<bool(const std::string&)>& is_reply);

  std::unique_ptr<ChildProcess> process_;
};

/// Runs `argv` (program first) to completion with stdin closed; its exit status and output.
struct RunResult {
  std::optional<int> status;  ///< nullopt: still running after the patience (then killed)
  std::string out;            ///< stdout
  std::string err;            ///< stderr
};
RunResult RunToCompletion(const TempDir& dir, const std::vector<std::string>& argv);

/// A received frame with the time this process saw it.
struct SeenFrame {
  CanFrame frame;
  std::chrono::steady_clock::time_point at;
  std::string text;  ///< candump form, "705#7F"
};

/// The test's CANopen master: a BrokerClientPort and an SdoClient on an io_context that runs only
/// inside this object's calls (RunUntil and the blocking helpers).
class BusMaster {
 public:
  explicit BusMaster(const std::string& endpoint, const std::string& name = "test-master");
  ~BusMaster();
  BusMaster(const BusMaster&) = delete;
  BusMaster& operator=(const BusMaster&) = delete;

  /// Runs the io_context until `condition` holds; false after `timeout`.
  bool RunUntil(const std::function<bool()>& condition, std::chrono::milliseconds timeout = kPatience);
  /// Runs the io_context for `duration` (to let traffic flow; never used to wait for a result).
  void RunFor(std::chrono::milliseconds duration);
  bool WaitConnected() {
    return RunUntil([this] { return port_->Connected(); });
  }

  struct Upload {
    canopen::SdoAbort abort = canopen::SdoAbort::kTimeout;
    canopen::Bytes data;
  };
  /// SDO upload (kAuto: expedited or segmented as the server chooses), waited for.
  Upload Read(std::uint8_t node, std::uint16_t index, std::uint8_t sub);
  /// SDO download, waited for.
  canopen::SdoAbort Download(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                             const canopen::Bytes& data);
  /// Little-endian `size`-byte integer download.
  canopen::SdoAbort Write(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint64_t value,
                          int size);
  /// Upload as an unsigned little-endian integer; nullopt on an abort.
  std::optional<std::uint64_t> ReadUnsigned(std::uint8_t node, std::uint16_t index, std::uint8_t sub);

  /// NMT command (CiA 301 §7.2.8.3.1: 000h, command specifier, node-ID; 0 = all nodes).
  bool Nmt(std::uint8_t command, std::uint8_t node);
  static constexpr std::uint8_t kNmtStart = 0x01;
  static constexpr std::uint8_t kNmtStop = 0x02;
  static constexpr std::uint8_t kNmtPreOperational = 0x80;
  static constexpr std::uint8_t kNmtResetNode = 0x81;

  /// Every frame received so far.
  const std::vector<SeenFrame>& Frames() const { return frames_; }
  /// Waits for a frame received at or after position `from` of Frames() that satisfies `match`.
  std::optional<SeenFrame> WaitForFrame(const std::function<bool(const SeenFrame&)>& match,
                                        std::size_t from = 0, std::chrono::milliseconds timeout = kPatience);
  /// Waits for a frame whose candump text is exactly `text` ("705#00"), from position `from`.
  std::optional<SeenFrame> WaitForFrame(const std::string& text, std::size_t from = 0,
                                        std::chrono::milliseconds timeout = kPatience);

  BrokerClientPort& port() { return *port_; }

 private:
  asio::io_context io_;
  AsioScheduler scheduler_{io_};
  std::unique_ptr<BrokerClientPort> port_;
  std::unique_ptr<canopen::SdoClient> sdo_;
  std::vector<SeenFrame> frames_;
};

/// "06020000h (object does not exist in the object dictionary)" for failure messages.
std::string AbortText(canopen::SdoAbort abort);
/// Hex of bytes, "E8 03".
std::string HexBytes(const canopen::Bytes& bytes);
/// Little-endian encoding of the low `size` bytes of `value`.
canopen::Bytes Le(std::uint64_t value, int size);

}  // namespace canfleet::system_test
