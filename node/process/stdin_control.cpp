#include "node/process/stdin_control.hpp"

#include <unistd.h>

#include <spdlog/spdlog.h>
#include <asio/read_until.hpp>
#include <iostream>
#include <istream>
#include <sstream>

namespace canfleet::node {

StdinControl::StdinControl(asio::io_context& io, devices::DeviceNode& node)
    : input_(io, ::dup(STDIN_FILENO)), node_(node) {}

void StdinControl::Start() {
  ReadLine();
}

void StdinControl::ReadLine() {
  asio::async_read_until(input_, buffer_, '\n', [this](const asio::error_code& ec, std::size_t) {
    if (ec) return;  // EOF: the controlling process went away; the node keeps running
    std::istream stream(&buffer_);
    std::string line;
    std::getline(stream, line);
    std::cout << Execute(node_, line) << std::endl;
    ReadLine();
  });
}

std::string StdinControl::Execute(devices::DeviceNode& node, const std::string& line) {
  std::istringstream in(line);
  std::string command, name, value;
  in >> command >> name;
  std::getline(in >> std::ws, value);
  auto& io = node.io();
  if (command == "set") {
    if (name.empty() || value.empty()) return "error: usage: set NAME VALUE";
    auto status = io.SetText(name, value);
    if (!status.ok()) return "error: " + status.error;
    if (!status.notice.empty()) spdlog::warn("simulated I/O: {}", status.notice);
    return "ok";
  }
  if (command == "get") {
    const devices::IoName resolved = io.Resolve(name);
    if (resolved.signal == nullptr) return "error: " + resolved.error.error;
    if (!resolved.notice.empty()) spdlog::warn("simulated I/O: {}", resolved.notice);
    const std::string unit = resolved.Unit();
    return name + " " + resolved.ValueText() + (unit.empty() ? "" : " " + unit);
  }
  if (command == "list") {
    std::string out;
    for (const auto& signal : io.Signals())
      out += signal->name() + " " + signal->ToString() + "\n";
    return out + "end";
  }
  if (command == "nmt") {
    std::string out;
    for (std::size_t p = 0; p < node.PortCount(); ++p) {
      if (p) out += " ";
      out += canopen::ToString(node.stack(p).State());
    }
    return out;
  }
  return "error: unknown command '" + command + "' (set, get, list, nmt)";
}

}  // namespace canfleet::node
