#include "bus/socketcan/socketcan_bridge.hpp"

namespace canfleet {

SocketCanOptions SocketCanBridge::BridgeOptions(SocketCanOptions options) {
  options.loopback = true;
  options.receive_own_messages = false;
  return options;
}

SocketCanBridge::SocketCanBridge(asio::io_context& io, std::string_view interface,
                                 VirtualBusSink to_virtual_bus, SocketCanOptions options)
    : to_virtual_bus_(std::move(to_virtual_bus)), socket_(io, interface, BridgeOptions(options)) {
  socket_.Start([this](std::span<const CanFrame> frames, std::span<const BusTime>) { OnBatch(frames); },
                [this](std::error_code code) {
                  if (on_error_) on_error_(code);
                });
}

SocketCanBridge::~SocketCanBridge() {
  alive_.reset();
}

void SocketCanBridge::OnBatch(std::span<const CanFrame> frames) {
  const std::weak_ptr<int> alive = alive_;
  // Runs of data/remote frames go to the sink as they are (no copy); error frames split them.
  std::size_t run_start = 0;
  auto flush_run = [&](std::size_t end) {
    if (end == run_start) return;
    const auto run = frames.subspan(run_start, end - run_start);
    if (!to_virtual_bus_) {
      stats_.dropped += run.size();
      return;
    }
    stats_.to_virtual_bus += run.size();
    to_virtual_bus_(run);
  };
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (!frames[i].error()) continue;
    flush_run(i);
    if (alive.expired()) return;
    run_start = i + 1;
    if (auto event = tracker_.OnErrorFrame(frames[i]); event && on_state_) on_state_(*event);
    if (alive.expired()) return;
  }
  flush_run(frames.size());
}

std::size_t SocketCanBridge::FromVirtualBus(std::span<const CanFrame> frames) {
  if (tracker_.State() == ControllerState::kBusOff) {
    stats_.dropped += frames.size();
    return 0;
  }
  std::size_t queued = 0;
  std::size_t run_start = 0;
  auto send_run = [&](std::size_t end) {
    if (end == run_start) return;
    queued += socket_.Send(frames.subspan(run_start, end - run_start));
  };
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (!frames[i].error()) continue;
    send_run(i);
    run_start = i + 1;
  }
  send_run(frames.size());
  stats_.to_socketcan += queued;
  stats_.dropped += frames.size() - queued;
  return queued;
}

void SocketCanBridge::ConnectTo(BusPort& port) {
  to_virtual_bus_ = [&port](std::span<const CanFrame> frames) {
    for (const CanFrame& frame : frames)
      port.Send(frame);
  };
  port.OnReceive(
      [this](const CanFrame& frame, BusTime) { FromVirtualBus(std::span<const CanFrame>(&frame, 1)); });
}

}  // namespace canfleet
