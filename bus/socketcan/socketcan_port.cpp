#include "bus/socketcan/socketcan_port.hpp"

namespace canfleet {

SocketCanPort::SocketCanPort(asio::io_context& io, std::string_view interface, SocketCanPortOptions options)
    : options_(options), socket_(io, interface, options.socket) {
  socket_.Start(
      [this](std::span<const CanFrame> frames, std::span<const BusTime> times) { OnBatch(frames, times); },
      [this](std::error_code code) {
        if (on_error_) on_error_(code);
      });
}

SocketCanPort::~SocketCanPort() {
  alive_.reset();
}

bool SocketCanPort::Send(const CanFrame& frame) {
  if (!frame.valid() || frame.error() || tracker_.State() == ControllerState::kBusOff) return false;
  return socket_.Send(frame);
}

void SocketCanPort::OnBatch(std::span<const CanFrame> frames, std::span<const BusTime> times) {
  const std::weak_ptr<int> alive = alive_;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const CanFrame& frame = frames[i];
    if (frame.error()) {
      if (auto event = tracker_.OnErrorFrame(frame)) NotifyState(*event);
      if (alive.expired()) return;
      if (!options_.deliver_error_frames) continue;
    }
    Deliver(frame, times[i]);
    if (alive.expired()) return;
  }
}

}  // namespace canfleet
