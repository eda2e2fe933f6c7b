#include "node/canopen/nmt/nmt_slave.hpp"

#include <utility>

namespace canfleet::canopen {

NmtSlave::NmtSlave(BusPort& port, std::uint8_t node_id, Callbacks callbacks)
    : port_(port), node_id_(node_id), callbacks_(std::move(callbacks)) {}

void NmtSlave::Boot(bool start_operational) {
  start_operational_ = start_operational;
  Enter(NmtState::kInitialising);
  // An unconfigured LSS slave (node-ID FFh) stays in Initialising and sends nothing (CiA 305 §3.4).
  if (!IsValidNodeId(node_id_)) return;
  // CiA 301 §7.2.8.3.3: the boot-up message marks Initialising → Pre-operational.
  port_.Send(CanFrame::Data(kErrorControlCobId + node_id_, {0x00}));
  Enter(start_operational ? NmtState::kOperational : NmtState::kPreOperational);
}

bool NmtSlave::OnFrame(const CanFrame& frame) {
  if (frame.id != kNmtCobId || frame.extended() || frame.remote() || frame.error()) return false;
  // CiA 301 §7.2.8.3.1 defines the command with exactly two data bytes; other lengths are not
  // NMT commands (the same rule as Lely's nmt.c and CANopenNode's CO_NMT_receive).
  if (frame.dlc != 2) return false;
  const std::uint8_t target = frame.data[1];
  const bool for_us = target == 0 || (IsValidNodeId(node_id_) && target == node_id_);
  if (for_us) Execute(static_cast<NmtCommand>(frame.data[0]));
  return true;
}

void NmtSlave::Execute(NmtCommand command) {
  if (state_ == NmtState::kInitialising) return;
  // CiA 301 §7.3.2, figure 48: start, stop and enter pre-operational are accepted in every
  // state after boot-up (a command for the current state changes nothing); both resets too.
  switch (command) {
    case NmtCommand::kStart:
      Enter(NmtState::kOperational);
      break;
    case NmtCommand::kStop:
      Enter(NmtState::kStopped);
      break;
    case NmtCommand::kEnterPreOperational:
      Enter(NmtState::kPreOperational);
      break;
    case NmtCommand::kResetNode:
      Enter(NmtState::kInitialising);
      if (callbacks_.reset_node) {
        callbacks_.reset_node();
      } else {
        Boot(start_operational_);
      }
      break;
    case NmtCommand::kResetCommunication:
      Enter(NmtState::kInitialising);
      if (callbacks_.reset_communication) {
        callbacks_.reset_communication();
      } else {
        Boot(start_operational_);
      }
      break;
  }
  // Any other command specifier: not defined by CiA 301, ignored.
}

void NmtSlave::SetState(NmtState state) {
  if (state_ == NmtState::kInitialising) return;
  switch (state) {
    case NmtState::kStopped:
    case NmtState::kOperational:
    case NmtState::kPreOperational:
      Enter(state);
      break;
    case NmtState::kInitialising:
      break;
  }
}

void NmtSlave::Enter(NmtState state) {
  if (state == state_) return;
  state_ = state;
  if (callbacks_.state_changed) callbacks_.state_changed(state);
}

}  // namespace canfleet::canopen
