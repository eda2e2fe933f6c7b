#pragma once
/// @file How a virtual bus and a port on it are set up.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>

#include "clock/scheduler.hpp"

namespace canfleet::broker {

struct BusConfig {
  std::string name{};               ///< "can0"; unique within a Broker
  std::uint32_t bitrate = 500'000;  ///< bit/s, 10 000 .. 1 000 000 (classical CAN)
  /// Paced: arbitration and exact frame durations on the bus's time line. Unpaced: no timing
  /// model, FIFO in submission order, as fast as the host allows (throughput tests).
  bool paced = true;
  /// Frames a port may have waiting; more are dropped and counted (like a CAN driver's queue).
  std::size_t tx_queue_capacity = 1024;
  /// Bus-off ports recover by themselves after 128 × 11 recessive bits (ISO 11898-1:2015
  /// §12.1.4.2). When false, only Broker::RecoverBusOff brings them back (like a Linux CAN
  /// interface with restart-ms 0). FaultStage::ForceBusOff(port, hold = true) holds one port
  /// bus-off until RecoverBusOff on a bus that recovers by itself.
  bool auto_recover = true;
  /// Sliding window of the load, frames/s and per-identifier figures.
  Duration stats_window = std::chrono::seconds(1);
};

/// How a port takes part in the bus.
struct AttachOptions {
  /// Bus monitoring: the port receives but never acknowledges, transmits or counts errors, so a
  /// capture tool does not keep a lone node from seeing its ACK errors. Its Submit()s are refused.
  bool listen_only = false;
  /// Also deliver error frames: when a transfer fails, a CanFrame with kError set, the failed
  /// frame's identifier and format flag, DLC 0, at the end of the error frame. Off for nodes: a
  /// CANopen stack has no use for them; captures want them.
  bool error_frames = false;
  /// The bit rate the port's controller runs at, bit/s (10 000..1 000 000); 0 = the bus's rate.
  /// A port at another rate than the transmitter of a frame does not receive it: it sees an error
  /// frame and counts a receive error (README "Bit rate").
  std::uint32_t bitrate = 0;
};

}  // namespace canfleet::broker
