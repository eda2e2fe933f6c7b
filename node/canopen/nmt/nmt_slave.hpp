#pragma once
/// @file The NMT slave state machine (CiA 301 v4.2 §7.2.8.2.1 module control, §7.3.2 state diagram,
/// figure 48): boot-up, the NMT commands on COB-ID 000h and local transitions (1029h reactions).
///
/// NMT command (master → slaves), COB-ID 000h, DLC 2 (CiA 301 §7.2.8.3.1):
///   byte 0: command specifier (01h start, 02h stop, 80h enter pre-operational,
///           81h reset node, 82h reset communication)
///   byte 1: node-ID addressed, 00h = all nodes
/// Boot-up (slave → master), COB-ID 700h + node-ID, DLC 1 (CiA 301 §7.2.8.3.3):
///   byte 0: 00h

#include <cstdint>
#include <functional>
#include <vector>

#include "bus/bus_port.hpp"
#include "bus/can_frame.hpp"
#include "node/canopen/common/nmt_state.hpp"
#include "node/canopen/nmt/error_control.hpp"

namespace canfleet::canopen {

/// The NMT slave of one node. It owns the NMT state; the stack owns the reset sequence.
///
/// Reset node and reset communication (CiA 301 §7.3.2, figure 48) first enter Initialising (services see
/// the change and stop), then hand over to the stack through a callback; the stack restores the
/// parameters of the reset area and calls Boot(), which sends the boot-up frame again.
///
/// While Initialising (before the first Boot(), during a reset, or with no valid node-ID) NMT
/// commands and SetState() are ignored: the node is not on the network yet.
class NmtSlave {
 public:
  struct Callbacks {
    /// NMT 81h: the stack restores application + communication parameters, then calls Boot().
    std::function<void()> reset_node;
    /// NMT 82h: the stack restores communication parameters, then calls Boot().
    std::function<void()> reset_communication;
    /// Every state change, including the one to Initialising at a reset (services gate on it).
    std::function<void(NmtState)> state_changed;
  };

  /// @param port the bus the boot-up frame goes to; must outlive the slave.
  /// @param node_id 1..127; anything else (e.g. FFh, an unconfigured LSS slave) keeps the slave in
  ///        Initialising until SetNodeId() gives it a valid ID and Boot() runs.
  /// A missing reset callback makes the slave boot again by itself (nothing to restore).
  NmtSlave(BusPort& port, std::uint8_t node_id, Callbacks callbacks);

  /// Initialising → boot-up frame 700h+id [00] → Pre-operational, or Operational when
  /// `start_operational` (devices with a "start in operational" option, e.g. 5555h).
  /// Does nothing but stay in Initialising when the node-ID is not 1..127.
  void Boot(bool start_operational = false);

  /// Handles an NMT command. Returns true for every NMT frame (standard data frame, COB-ID 000h,
  /// DLC 2), whoever it addresses, since no other service uses 000h; false for anything else
  /// (including 000h with DLC ≠ 2, which CiA 301 does not define and the slave ignores).
  bool OnFrame(const CanFrame& frame);
  /// The 11-bit identifiers it listens to (an acceptance filter, broker README "Virtual time").
  static void AddListenedIds(std::vector<std::uint32_t>& ids) { ids.push_back(0x000); }

  /// Executes an NMT command locally, as if received (LSS switch to waiting, self-start).
  /// Unknown command specifiers are ignored.
  void Execute(NmtCommand command);

  NmtState State() const { return state_; }

  /// Local transition to Stopped, Pre-operational or Operational (1029h error behaviour, device
  /// logic). Ignored while Initialising and for kInitialising (use a reset for that).
  void SetState(NmtState state);

  /// The node-ID the slave answers to and announces its boot-up with; takes effect at once.
  void SetNodeId(std::uint8_t node_id) { node_id_ = node_id; }
  std::uint8_t NodeId() const { return node_id_; }

 private:
  void Enter(NmtState state);

  BusPort& port_;
  std::uint8_t node_id_;
  Callbacks callbacks_;
  NmtState state_ = NmtState::kInitialising;
  bool start_operational_ = false;  // remembered for a self-boot without reset callbacks
};

}  // namespace canfleet::canopen
