#pragma once
/// @file A capture attached to a broker bus: a port that only listens and writes every frame it
/// sees to a CaptureWriter. Stamps are bus time + the process's wall-clock origin
/// (clock/wall_clock.hpp), the same origin socketcand uses.

#include <cstdint>
#include <span>

#include "bus/capture/capture_writer.hpp"
#include "clock/wall_clock.hpp"
#include "orchestrator/broker/bus_config.hpp"
#include "orchestrator/broker/port_sink.hpp"

namespace canfleet::capture {

/// Writes every frame delivered to its port, stamped origin + bus time. Attach it with
/// CaptureTap::kAttachOptions: listen-only (it never acknowledges or transmits, so it does not
/// change the bus it watches: a lone node still sees its ACK errors) and with error frames.
///
///     capture::PcapWriter pcap("can0.pcap");
///     capture::CaptureTap tap(pcap, WallClockOrigin(scheduler));  // or the host's one origin
///     auto port = broker.Attach("can0", "capture", tap, capture::CaptureTap::kAttachOptions);
class CaptureTap final : public broker::PortSink {
 public:
  static constexpr broker::AttachOptions kAttachOptions{.listen_only = true, .error_frames = true};

  /// `writer` must outlive the tap.
  CaptureTap(CaptureWriter& writer, WallTime origin) : writer_(writer), origin_(origin) {}

  void Deliver(std::span<const broker::TimedFrame> frames) override;
  /// A listen-only port's controller never changes state; nothing to write.
  void ControllerChanged(const ControllerEvent& event) override { (void)event; }

  std::uint64_t frames() const { return frames_; }

 private:
  CaptureWriter& writer_;
  WallTime origin_;
  std::uint64_t frames_ = 0;
};

}  // namespace canfleet::capture
