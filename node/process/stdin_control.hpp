#pragma once
/// @file A node-local control interface on standard input, one command per line, for tests and
/// scripts until the orchestrator's control API drives the node:
///   set IN1.voltage_mV 3000   → "ok" or "error: <reason>"
///   get OUT1.current_mA       → "OUT1.current_mA 1234"
///   list                       → every signal, one per line, then "end"
///   nmt                        → the NMT state of each port
/// Replies go to standard output, one line each (flushed), so a test can read them back.

#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>
#include <asio/streambuf.hpp>
#include <string>

#include "node/devices/device_node.hpp"

namespace canfleet::node {

class StdinControl {
 public:
  StdinControl(asio::io_context& io, devices::DeviceNode& node);
  void Start();

  /// Executes one command line and returns the reply (without the newline).
  static std::string Execute(devices::DeviceNode& node, const std::string& line);

 private:
  void ReadLine();

  asio::posix::stream_descriptor input_;
  asio::streambuf buffer_;
  devices::DeviceNode& node_;
};

}  // namespace canfleet::node
