#pragma once
/// @file The buses as a monitor sees them (listen-only, error frames too: the wire protocol's
/// monitor role), for canfleet web's CANopen-Diag statistics. Its own file and thread: it is built
/// on standalone Asio (the node wire client), the web server on Boost.Asio.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "bus/can_frame.hpp"

namespace canfleet::web {

class BusMonitor {
 public:
  /// `time_ns`: the frame's end on the bus's time line (simulated in virtual time).
  using FrameHandler =
      std::function<void(const std::string& bus, const CanFrame& frame, std::int64_t time_ns)>;
  /// Watches buses of the broker at `endpoint` (tcp://HOST:PORT, unix:///path); `on_frame` runs
  /// on the monitor's thread.
  /// `token`: the fleet's, for a broker beyond loopback (empty: none).
  BusMonitor(std::string endpoint, std::string token, FrameHandler on_frame);
  ~BusMonitor();
  BusMonitor(const BusMonitor&) = delete;
  BusMonitor& operator=(const BusMonitor&) = delete;
  /// Starts watching `bus` (once; thread-safe). A bus the broker does not have is logged and retried.
  void Watch(const std::string& bus);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace canfleet::web
