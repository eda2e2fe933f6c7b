#include "node/canopen/lss/lss_slave.hpp"

#include <chrono>

namespace canfleet::canopen {

namespace {

std::uint32_t Le32(const CanFrame& frame) {
  return static_cast<std::uint32_t>(frame.data[1]) | static_cast<std::uint32_t>(frame.data[2]) << 8 |
         static_cast<std::uint32_t>(frame.data[3]) << 16 | static_cast<std::uint32_t>(frame.data[4]) << 24;
}

bool ValidNodeId(std::uint8_t node_id) {
  return (node_id >= 1 && node_id <= 127) || node_id == kLssUnconfigured;
}

}  // namespace

std::uint32_t LssAddress::Part(std::uint8_t lss_sub) const {
  switch (lss_sub) {
    case 0:
      return vendor_id;
    case 1:
      return product_code;
    case 2:
      return revision;
    default:
      return serial;
  }
}

LssSlave::LssSlave(BusPort& port, Scheduler& scheduler, LssAddress address, std::uint8_t active_node_id,
                   std::uint8_t bit_timing_index, Callbacks callbacks)
    : port_(port),
      address_(address),
      callbacks_(std::move(callbacks)),
      active_node_id_(active_node_id),
      pending_node_id_(active_node_id),
      active_bit_timing_(bit_timing_index),
      pending_bit_timing_(bit_timing_index),
      switch_timer_(scheduler, [this] { OnSwitchTimer(); }) {}

void LssSlave::SetActiveNodeId(std::uint8_t node_id) {
  active_node_id_ = node_id;
  pending_node_id_ = node_id;
}

bool LssSlave::OnFrame(const CanFrame& frame) {
  if (frame.id != kLssMasterToSlaveId || frame.extended() || frame.error()) return false;
  // CiA 305: LSS frames always carry 8 bytes; CANopenNode and c-open drop anything else.
  if (frame.remote() || frame.dlc != 8) return true;
  // CiA 305 fig. 35: nobody talks during the two switch delays; a request now is a master error.
  if (SwitchingBitTiming()) return true;

  const auto cs = static_cast<LssCs>(frame.data[0]);
  switch (cs) {
    case LssCs::kSwitchStateGlobal:
      OnSwitchStateGlobal(frame);
      return true;
    case LssCs::kSwitchSelectiveVendor:
    case LssCs::kSwitchSelectiveProduct:
    case LssCs::kSwitchSelectiveRevision:
    case LssCs::kSwitchSelectiveSerial:
      // A slave already in configuration ignores selection (CiA 305 fig. 32 starts from waiting).
      if (mode_ == Mode::kWaiting) OnSwitchStateSelective(cs, Le32(frame));
      return true;
    case LssCs::kIdentifyRemoteVendor:
    case LssCs::kIdentifyRemoteProduct:
    case LssCs::kIdentifyRemoteRevisionLow:
    case LssCs::kIdentifyRemoteRevisionHigh:
    case LssCs::kIdentifyRemoteSerialLow:
    case LssCs::kIdentifyRemoteSerialHigh:
      // Identification works in both modes (lely-core: waiting and configuration states).
      OnIdentifyRemote(cs, Le32(frame));
      return true;
    case LssCs::kIdentifyNonConfigured:
      OnIdentifyNonConfigured();
      return true;
    case LssCs::kFastscan:
      if (mode_ == Mode::kWaiting) OnFastscan(frame);
      return true;
    default:
      break;
  }

  // Configuration and inquiry services: configuration mode only (CANopenNode, c-open, lely-core).
  if (mode_ != Mode::kConfiguration) return true;
  switch (cs) {
    case LssCs::kConfigureNodeId:
      OnConfigureNodeId(frame.data[1]);
      break;
    case LssCs::kConfigureBitTiming:
      OnConfigureBitTiming(frame.data[1], frame.data[2]);
      break;
    case LssCs::kActivateBitTiming:
      OnActivateBitTiming(static_cast<std::uint16_t>(frame.data[1] | frame.data[2] << 8));
      break;
    case LssCs::kStoreConfiguration:
      OnStoreConfiguration();
      break;
    case LssCs::kInquireVendor:
      Reply32(cs, address_.vendor_id);
      break;
    case LssCs::kInquireProduct:
      Reply32(cs, address_.product_code);
      break;
    case LssCs::kInquireRevision:
      Reply32(cs, address_.revision);
      break;
    case LssCs::kInquireSerial:
      Reply32(cs, address_.serial);
      break;
    case LssCs::kInquireNodeId:
      // CiA 305 fig. 41: the active node-ID; FFh while non-configured.
      Reply(cs, active_node_id_);
      break;
    default:
      break;  // unknown or master-only command specifiers are ignored
  }
  return true;
}

// CiA 305 fig. 31. Leaving configuration with a new pending node-ID makes the slave take it: the
// manuals describe it as the module resetting itself to pre-operational with the new ID.
void LssSlave::OnSwitchStateGlobal(const CanFrame& frame) {
  switch (static_cast<LssModeRequest>(frame.data[1])) {
    case LssModeRequest::kWaiting: {
      mode_ = Mode::kWaiting;
      selective_next_ = 0;
      if (pending_node_id_ != active_node_id_) {
        const std::uint8_t new_id = pending_node_id_;
        active_node_id_ = new_id;
        if (callbacks_.apply_node_id) callbacks_.apply_node_id(new_id);
      }
      break;
    }
    case LssModeRequest::kConfiguration:
      mode_ = Mode::kConfiguration;
      break;
    default:
      break;  // reserved mode values are ignored
  }
}

// CiA 305 fig. 32: vendor-ID, product code, revision and serial number in this order; the slave
// answers 44h and enters configuration only if all four equal its LSS address. Any mismatch or
// out-of-order part restarts the sequence (as lely-core does), so stale parts never combine.
void LssSlave::OnSwitchStateSelective(LssCs cs, std::uint32_t value) {
  const auto code = static_cast<std::uint8_t>(cs);
  const auto first = static_cast<std::uint8_t>(LssCs::kSwitchSelectiveVendor);
  if ((code != first && code != selective_next_) ||
      value != address_.Part(static_cast<std::uint8_t>(code - first))) {
    selective_next_ = 0;
    return;
  }
  if (cs != LssCs::kSwitchSelectiveSerial) {
    selective_next_ = static_cast<std::uint8_t>(code + 1);
    return;
  }
  selective_next_ = 0;
  mode_ = Mode::kConfiguration;
  Reply(LssCs::kSwitchSelectiveResponse);
}

// CiA 305 fig. 42/43: vendor-ID and product code exact, revision and serial number within the
// inclusive ranges [low, high]; the slave answers 4Fh after the last part if everything matched.
void LssSlave::OnIdentifyRemote(LssCs cs, std::uint32_t value) {
  const auto code = static_cast<std::uint8_t>(cs);
  const auto first = static_cast<std::uint8_t>(LssCs::kIdentifyRemoteVendor);
  bool match = false;
  switch (cs) {
    case LssCs::kIdentifyRemoteVendor:
      match = value == address_.vendor_id;
      break;
    case LssCs::kIdentifyRemoteProduct:
      match = value == address_.product_code;
      break;
    case LssCs::kIdentifyRemoteRevisionLow:
      match = value <= address_.revision;
      break;
    case LssCs::kIdentifyRemoteRevisionHigh:
      match = value >= address_.revision;
      break;
    case LssCs::kIdentifyRemoteSerialLow:
      match = value <= address_.serial;
      break;
    case LssCs::kIdentifyRemoteSerialHigh:
      match = value >= address_.serial;
      break;
    default:
      break;
  }
  if ((code != first && code != identify_next_) || !match) {
    identify_next_ = 0;
    return;
  }
  if (cs != LssCs::kIdentifyRemoteSerialHigh) {
    identify_next_ = static_cast<std::uint8_t>(code + 1);
    return;
  }
  identify_next_ = 0;
  Reply(LssCs::kIdentifySlave);
}

// CiA 305 fig. 44/45: only a slave with neither an active nor a pending node-ID answers
// (lely-core checks both, so a slave that was just given an ID is not found twice).
void LssSlave::OnIdentifyNonConfigured() {
  if (NonConfigured()) Reply(LssCs::kIdentifyNonConfiguredSlave);
}

// CiA 305 fig. 46, Fastscan. Frame: b1–4 IDNumber, b5 BitChecked, b6 LSSSub, b7 LSSNext.
// Only non-configured slaves in waiting take part. BitChecked 80h resets LSSPos and every such
// slave answers. Otherwise a slave whose LSSPos equals LSSSub answers 4Fh when the bits
// BitChecked..31 of IDNumber equal those of its address part; it then moves LSSPos to LSSNext,
// and a confirmed last part (BitChecked 0, LSSNext < LSSSub) takes it to configuration.
void LssSlave::OnFastscan(const CanFrame& frame) {
  if (!NonConfigured()) return;
  const std::uint32_t id_number = Le32(frame);
  const std::uint8_t bit_checked = frame.data[5];
  const std::uint8_t lss_sub = frame.data[6];
  const std::uint8_t lss_next = frame.data[7];
  if ((bit_checked > 31 && bit_checked != kFastscanReset) || lss_sub > 3 || lss_next > 3) return;
  if (bit_checked == kFastscanReset) {
    fastscan_pos_ = 0;
    Reply(LssCs::kIdentifySlave);
    return;
  }
  if (fastscan_pos_ != lss_sub) return;
  const std::uint32_t mask = 0xFFFFFFFFu << bit_checked;
  if (((address_.Part(lss_sub) ^ id_number) & mask) != 0) return;
  fastscan_pos_ = lss_next;
  if (bit_checked == 0 && lss_next < lss_sub) mode_ = Mode::kConfiguration;
  Reply(LssCs::kIdentifySlave);
}

// CiA 305 fig. 33: 1..127 or FFh (back to non-configured) become the pending node-ID.
void LssSlave::OnConfigureNodeId(std::uint8_t node_id) {
  if (!ValidNodeId(node_id)) {
    Reply(LssCs::kConfigureNodeId, kLssOutOfRange);
    return;
  }
  pending_node_id_ = node_id;
  Reply(LssCs::kConfigureNodeId, kLssOk);
}

// CiA 305 fig. 34: only table selector 0 (the CiA 301 table) is supported; its reserved index 5
// and automatic detection (9) are refused like CANopenNode and c-open do.
void LssSlave::OnConfigureBitTiming(std::uint8_t table, std::uint8_t index) {
  if (table != 0 || !BitRateKbit(index)) {
    Reply(LssCs::kConfigureBitTiming, kLssOutOfRange);
    return;
  }
  pending_bit_timing_ = index;
  Reply(LssCs::kConfigureBitTiming, kLssOk);
}

// CiA 305 fig. 35: wait the switch delay, switch to the pending bit rate, wait the switch delay
// again before anything is sent. No reply. Runs on the scheduler, never blocks the node.
void LssSlave::OnActivateBitTiming(std::uint16_t delay_ms) {
  switch_delay_ = std::chrono::milliseconds(delay_ms);
  switch_phase_ = SwitchPhase::kBeforeSwitch;
  switch_timer_.StartAfter(switch_delay_);
}

void LssSlave::OnSwitchTimer() {
  if (switch_phase_ == SwitchPhase::kBeforeSwitch) {
    active_bit_timing_ = pending_bit_timing_;
    switch_phase_ = SwitchPhase::kAfterSwitch;
    switch_timer_.StartAfter(switch_delay_);
    if (callbacks_.activate_bit_timing) callbacks_.activate_bit_timing(active_bit_timing_);
    return;
  }
  switch_phase_ = SwitchPhase::kIdle;
}

// CiA 305 fig. 36: persist the pending node-ID and bit timing.
void LssSlave::OnStoreConfiguration() {
  if (!callbacks_.store_configuration) {
    Reply(LssCs::kStoreConfiguration, kLssNotSupported);
    return;
  }
  const bool stored = callbacks_.store_configuration(pending_node_id_, pending_bit_timing_);
  Reply(LssCs::kStoreConfiguration, stored ? kLssOk : kLssStorageError);
}

void LssSlave::Reply(LssCs cs, std::uint8_t b1, std::uint8_t b2) {
  port_.Send(LssFrame(kLssSlaveToMasterId, cs, {b1, b2}));
}

void LssSlave::Reply32(LssCs cs, std::uint32_t value) {
  port_.Send(LssFrame32(kLssSlaveToMasterId, cs, value));
}

}  // namespace canfleet::canopen
