#include "tests/system/node/node_system_support.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace canfleet::system_test {

using namespace std::chrono_literals;

namespace {

std::vector<std::string> SplitLines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(line);
  return out;
}

}  // namespace

std::string AbortText(canopen::SdoAbort abort) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%08Xh", static_cast<unsigned>(abort));
  return std::string(buf) + " (" + canopen::Describe(abort) + ")";
}

std::string HexBytes(const canopen::Bytes& bytes) {
  std::string out;
  char buf[4];
  for (auto b : bytes) {
    std::snprintf(buf, sizeof buf, "%02X", b);
    if (!out.empty()) out += ' ';
    out += buf;
  }
  return out.empty() ? "(empty)" : out;
}

canopen::Bytes Le(std::uint64_t value, int size) {
  canopen::Bytes out(static_cast<std::size_t>(size));
  for (int i = 0; i < size; ++i)
    out[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(value >> (8 * i));
  return out;
}

// ---------------------------------------------------------------------------------------------
// BrokerProcess

BrokerProcess::BrokerProcess(const TempDir& dir, const std::string& listen) {
  static int instance = 0;
  const std::string tag = std::to_string(++instance);
  const std::string ready = dir.File("broker" + tag + ".ready");
  process_ = std::make_unique<ChildProcess>(
      std::vector<std::string>{PROGRAM_CANFLEET_BROKER, "--bus", "can0:500k", "--listen", listen,
                               "--ready-file", ready, "--log-level", "debug"},
      dir.File("broker" + tag + ".log"));
  if (!WaitUntil([&] { return std::filesystem::exists(ready) || !process_->Running(); }))
    ADD_FAILURE() << "broker not ready:\n" << process_->Log();
  // The ready file may be seen before its line is complete: read until a whole line is there.
  WaitUntil([&] {
    std::ifstream in(ready);
    std::string line;
    if (std::getline(in, line) && !in.eof()) endpoint_ = line;
    return !endpoint_.empty() || !process_->Running();
  });
  if (endpoint_.empty()) ADD_FAILURE() << "broker wrote no endpoint:\n" << process_->Log();
}

// ---------------------------------------------------------------------------------------------
// NodeProcess

NodeProcess::NodeProcess(const TempDir& dir, const std::string& tag, std::vector<std::string> args) {
  // The nodes publish their telemetry as shipped, but in a DDS domain of their own, so that
  // system tests running at the same time that watch the default domain never see them.
  ::setenv("CANFLEET_DDS_DOMAIN", "75", 0);
  args.insert(args.begin(), PROGRAM_CANFLEET_NODE);
  args.push_back("--stdin-control");
  process_ = std::make_unique<ChildProcess>(std::move(args), dir.File(tag + ".log"));
}

std::optional<std::string> NodeProcess::Command(const std::string& line,
                                                const std::function<bool(const std::string&)>& is_reply) {
  process_->WriteLine(line);
  return process_->WaitForLine(is_reply);
}

std::string NodeProcess::Set(const std::string& name, const std::string& value) {
  const auto reply = Command("set " + name + " " + value,
                             [](const std::string& l) { return l == "ok" || l.starts_with("error: "); });
  return reply.value_or("no reply");
}

std::optional<std::string> NodeProcess::Get(const std::string& name) {
  const auto reply = Command("get " + name, [&](const std::string& l) {
    return l.starts_with(name + " ") || l.starts_with("error: ");
  });
  if (!reply || reply->starts_with("error: ")) return std::nullopt;
  return reply->substr(name.size() + 1);
}

std::optional<double> NodeProcess::GetNumber(const std::string& name) {
  const auto text = Get(name);
  if (!text) return std::nullopt;
  try {
    return std::stod(*text);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::vector<std::string> NodeProcess::LogLines() {
  process_->Poll();
  std::vector<std::string> out = SplitLines(process_->Log());
  for (const auto& line : process_->Lines())
    if (line.starts_with("[")) out.push_back(line);
  return out;
}

std::vector<std::string> NodeProcess::AllLines() {
  process_->Poll();
  std::vector<std::string> out = SplitLines(process_->Log());
  for (const auto& line : process_->Lines())
    if (!line.empty()) out.push_back(line);
  return out;
}

std::string NodeProcess::Output() {
  process_->Poll();
  // Log lines only: the control replies (one per poll of a condition) would drown them.
  std::string out = "--- stderr:\n" + process_->Log() + "--- stdout (log lines):\n";
  for (const auto& line : process_->Lines())
    if (line.starts_with("[")) out += line + "\n";
  return out;
}

RunResult RunToCompletion(const TempDir& dir, const std::vector<std::string>& argv) {
  static int instance = 0;
  const std::string err_path = dir.File("run" + std::to_string(++instance) + ".err");
  ChildProcess child(argv, err_path);
  RunResult result;
  result.status = child.Wait();
  child.Poll();
  for (const auto& line : child.Lines())
    result.out += line + "\n";
  result.err = child.Log();
  return result;
}

// ---------------------------------------------------------------------------------------------
// BusMaster

BusMaster::BusMaster(const std::string& endpoint, const std::string& name) {
  BrokerClientOptions options;
  options.endpoint = endpoint;
  options.bus = "can0";
  options.node_name = name;
  port_ = std::make_unique<BrokerClientPort>(io_, options);
  canopen::SdoClientOptions sdo;
  sdo.timeout = std::chrono::seconds(3);  // a loaded machine: generous, never relied upon
  sdo_ = std::make_unique<canopen::SdoClient>(*port_, scheduler_, sdo);
  port_->OnReceive([this](const CanFrame& frame, BusTime) {
    frames_.push_back({frame, std::chrono::steady_clock::now(), ToCandump(frame)});
    sdo_->OnFrame(frame);
  });
}

BusMaster::~BusMaster() {
  // The client's timers live on the scheduler; drop them before the port and the io_context.
  sdo_.reset();
  port_.reset();
}

bool BusMaster::RunUntil(const std::function<bool()>& condition, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!condition()) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    io_.restart();
    io_.run_for(5ms);
  }
  return true;
}

void BusMaster::RunFor(std::chrono::milliseconds duration) {
  const auto deadline = std::chrono::steady_clock::now() + duration;
  RunUntil([&] { return std::chrono::steady_clock::now() >= deadline; }, duration + 1s);
}

BusMaster::Upload BusMaster::Read(std::uint8_t node, std::uint16_t index, std::uint8_t sub) {
  std::optional<Upload> result;
  if (!sdo_->Upload(node, index, sub, canopen::SdoMode::kAuto,
                    [&](canopen::SdoAbort abort, canopen::Bytes data) {
                      result = Upload{abort, std::move(data)};
                    }))
    return {};
  // The client's own timeout completes every transfer; the patience only guards a broken client.
  RunUntil([&] { return result.has_value(); }, kPatience);
  if (!result) sdo_->Abort(canopen::SdoAbort::kTimeout);
  return result.value_or(Upload{});
}

canopen::SdoAbort BusMaster::Download(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                                      const canopen::Bytes& data) {
  std::optional<canopen::SdoAbort> result;
  if (!sdo_->Download(node, index, sub, data, canopen::SdoMode::kAuto,
                      [&](canopen::SdoAbort abort) { result = abort; }))
    return canopen::SdoAbort::kGeneralError;
  RunUntil([&] { return result.has_value(); }, kPatience);
  if (!result) sdo_->Abort(canopen::SdoAbort::kTimeout);
  return result.value_or(canopen::SdoAbort::kTimeout);
}

canopen::SdoAbort BusMaster::Write(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                                   std::uint64_t value, int size) {
  return Download(node, index, sub, Le(value, size));
}

std::optional<std::uint64_t> BusMaster::ReadUnsigned(std::uint8_t node, std::uint16_t index,
                                                     std::uint8_t sub) {
  const Upload r = Read(node, index, sub);
  if (r.abort != canopen::SdoAbort::kNone) return std::nullopt;
  return canopen::DecodeUnsignedLe(r.data);
}

bool BusMaster::Nmt(std::uint8_t command, std::uint8_t node) {
  const bool sent = port_->Send(CanFrame::Data(0x000, {command, node}));
  RunFor(1ms);  // let the batch leave
  return sent;
}

std::optional<SeenFrame> BusMaster::WaitForFrame(const std::function<bool(const SeenFrame&)>& match,
                                                 std::size_t from, std::chrono::milliseconds timeout) {
  std::optional<SeenFrame> found;
  std::size_t next = from;
  RunUntil(
      [&] {
        for (; next < frames_.size(); ++next) {
          if (match(frames_[next])) {
            found = frames_[next];
            return true;
          }
        }
        return false;
      },
      timeout);
  return found;
}

std::optional<SeenFrame> BusMaster::WaitForFrame(const std::string& text, std::size_t from,
                                                 std::chrono::milliseconds timeout) {
  return WaitForFrame([&](const SeenFrame& f) { return f.text == text; }, from, timeout);
}

}  // namespace canfleet::system_test
