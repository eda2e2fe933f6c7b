#pragma once
/// @file Snapshots of a bus's and a port's counters, for telemetry (BusStats on DDS) and the
/// control API.

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "bus/bus_port.hpp"
#include "orchestrator/broker/port_sink.hpp"

namespace canfleet::broker {

/// Traffic of one identifier over the statistics window.
struct CobIdStats {
  std::uint32_t id = 0;
  bool extended = false;
  std::uint64_t frames = 0;  ///< acknowledged transfers in the window
  double frames_per_s = 0;
};

struct BusStats {
  std::string name;
  std::uint32_t bitrate = 0;
  bool paced = true;
  std::size_t ports = 0;
  BusTime time{};    ///< when the snapshot was taken (scheduler time)
  BusTime window{};  ///< length of time the rates below cover (≤ BusConfig::stats_window)

  /// Busy time / window in percent: transfers, error frames and the intermission after each
  /// (paced buses; always 0 on an unpaced bus, which has no time line).
  double load_percent = 0;
  double frames_per_s = 0;        ///< acknowledged transfers per second over the window
  double error_frames_per_s = 0;  ///< failed attempts (ACK errors, corrupted frames) per second
  /// The busiest identifiers over the window, most frames first (ties: lower id first).
  std::vector<CobIdStats> top_ids;

  // Totals since the bus was created.
  std::uint64_t frames = 0;        ///< acknowledged transfers
  std::uint64_t error_frames = 0;  ///< failed attempts
  std::uint64_t deliveries = 0;    ///< frames handed to receiving ports (a frame to 3 ports counts 3)
  std::uint64_t queue_drops = 0;   ///< frames refused because a port's TX queue was full
  std::uint64_t fault_drops = 0;   ///< deliveries suppressed by drop rules
  std::uint64_t fault_delays = 0;  ///< deliveries postponed by delay rules
};

struct PortStats {
  PortId id = 0;
  std::string bus;
  std::string name;
  ControllerEvent controller;  ///< state, TEC, REC now
  /// The bit rate the port's controller runs at (bit/s): the bus's unless the port stated another
  /// (AttachOptions::bitrate, Broker::SetPortBitrate).
  std::uint32_t bitrate = 0;
  std::size_t queued = 0;  ///< frames waiting in the TX queue (including one being retried)

  std::uint64_t tx_frames = 0;  ///< own frames acknowledged on the wire
  std::uint64_t rx_frames = 0;  ///< frames delivered to this port
  std::uint64_t tx_errors = 0;  ///< failed transmit attempts (ACK errors, corrupted frames)
  /// Receive errors: corrupted frames seen as a receiver, and transfers at another bit rate.
  std::uint64_t rx_errors = 0;
  std::uint64_t queue_drops = 0;    ///< submitted while the TX queue was full
  std::uint64_t invalid_drops = 0;  ///< invalid frames, error frames, or sent by a listen-only port
  std::uint64_t bus_off_drops = 0;  ///< submitted while bus-off, or flushed from the queue at bus-off
  std::uint64_t fault_drops = 0;    ///< deliveries to this port suppressed by drop rules
  /// Frames sent by FaultStage::StartBabbling (not in tx_frames: the node did not send them).
  std::uint64_t babble_frames = 0;
  /// Bus-off recovery attempts that failed because FaultStage::HoldBusOff held the port.
  std::uint64_t failed_recoveries = 0;
};

}  // namespace canfleet::broker
