#pragma once
/// @file The CiA 305 v3.0.0 LSS slave: lets an LSS master find a node by its LSS address (1018h
/// identity), give it a node-ID and a bit rate, and make both persistent.
///
/// LSS modes: after power-on a slave is in *waiting* mode. A master moves
/// slaves to *configuration* mode with switch state global (all slaves), switch state selective
/// (one slave, by its full LSS address) or Fastscan (one non-configured slave, found bit by bit).
/// Configuration and inquiry services are answered only in configuration mode.
///
/// Node-IDs: the *active* node-ID is the one the stack runs with; configure node-ID only sets the
/// *pending* one. When a master switches the slave back to waiting and the pending ID differs
/// from the active one, the slave calls `Callbacks::apply_node_id`; the stack then performs reset
/// communication with the new ID (the manuals: the module "resets itself back to pre-operational")
/// and reports the ID back through SetActiveNodeId().
///
/// A non-configured node (active ID FFh) takes part only in LSS: the stack keeps NMT, heartbeat,
/// SDO, EMCY and PDO off until it has an ID, and starts them from the apply_node_id callback. LSS
/// itself does not depend on the NMT state: the stack feeds it every frame in every state.
///
/// The stack also decides what NMT reset communication does with a pending ID that was never
/// switched to waiting: CiA 305 makes the pending ID active at the next reset communication, so
/// the stack should read PendingNodeId() there (SetActiveNodeId then confirms it).

#include <cstdint>
#include <functional>
#include <vector>

#include "bus/bus_port.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/lss/lss_protocol.hpp"

namespace canfleet::canopen {

/// The 128-bit LSS address: object 1018h sub 1–4 (CiA 305: vendor-ID, product code, revision
/// number, serial number).
struct LssAddress {
  std::uint32_t vendor_id = 0;
  std::uint32_t product_code = 0;
  std::uint32_t revision = 0;
  std::uint32_t serial = 0;

  /// Part `lss_sub` in Fastscan order (0 vendor, 1 product, 2 revision, 3 serial).
  std::uint32_t Part(std::uint8_t lss_sub) const;
  friend bool operator==(const LssAddress&, const LssAddress&) = default;
};

class LssSlave {
 public:
  /// How the slave reaches the stack. Callbacks are invoked from OnFrame() or from a timer on the
  /// node's event loop; they may call back into the slave (e.g. SetActiveNodeId).
  struct Callbacks {
    /// Switch state global to waiting while the pending node-ID differs from the active one
    /// (CiA 305 fig. 31). The stack performs NMT reset communication with `new_node_id` (1..127,
    /// or FFh: the node becomes non-configured) and then calls SetActiveNodeId(new_node_id).
    std::function<void(std::uint8_t new_node_id)> apply_node_id;
    /// Store configuration (CiA 305 fig. 36): persist the pending node-ID and the pending bit
    /// timing index. Returns false on a storage error (reply error 2). Empty = storing is not
    /// supported (reply error 1). Called synchronously; the reply goes out after it returns.
    std::function<bool(std::uint8_t node_id, std::uint8_t bit_timing_index)> store_configuration;
    /// Activate bit timing (CiA 305 fig. 35), called one switch delay after the request: the
    /// stack switches the bus port to the bit rate of table-0 index `bit_timing_index`.
    std::function<void(std::uint8_t bit_timing_index)> activate_bit_timing;
  };

  enum class Mode : std::uint8_t { kWaiting, kConfiguration };

  /// @param port sends the replies on 7E4h; must outlive the slave.
  /// @param scheduler runs the activate-bit-timing delays; must outlive the slave.
  /// @param address the node's LSS address (1018h sub 1–4).
  /// @param active_node_id 1..127, or kLssUnconfigured (FFh).
  /// @param bit_timing_index the active CiA 301 table index (4 = 125 kbit/s).
  LssSlave(BusPort& port, Scheduler& scheduler, LssAddress address, std::uint8_t active_node_id,
           std::uint8_t bit_timing_index, Callbacks callbacks);
  LssSlave(const LssSlave&) = delete;
  LssSlave& operator=(const LssSlave&) = delete;

  /// Handles a frame. Returns true for every standard data or remote frame on 7E5h (nothing else
  /// may interpret it), false for all other frames. Frames with DLC ≠ 8 are consumed and ignored,
  /// like CANopenNode and c-open do; so is every request while a bit timing switch is running.
  bool OnFrame(const CanFrame& frame);
  /// The 11-bit identifiers it listens to: the LSS master's 7E5h.
  static void AddListenedIds(std::vector<std::uint32_t>& ids) { ids.push_back(kLssMasterToSlaveId); }

  /// The node-ID the stack now runs with (after reset communication); also becomes the pending ID.
  void SetActiveNodeId(std::uint8_t node_id);
  /// The bit timing the port now runs at (set by the stack, e.g. from a device object at reset);
  /// also becomes the pending one, as after an activation.
  void SetBitTiming(std::uint8_t bit_timing_index) {
    active_bit_timing_ = bit_timing_index;
    pending_bit_timing_ = bit_timing_index;
  }
  /// Replaces the LSS address (e.g. after the device wrote a new serial number to 1018h).
  void SetAddress(const LssAddress& address) { address_ = address; }

  Mode CurrentMode() const { return mode_; }
  std::uint8_t ActiveNodeId() const { return active_node_id_; }
  std::uint8_t PendingNodeId() const { return pending_node_id_; }
  std::uint8_t ActiveBitTimingIndex() const { return active_bit_timing_; }
  std::uint8_t PendingBitTimingIndex() const { return pending_bit_timing_; }
  /// True from an activate bit timing request until the second switch delay has passed. CiA 305
  /// fig. 35 wants every node silent meanwhile; the stack may hold back its own transmissions.
  bool SwitchingBitTiming() const { return switch_phase_ != SwitchPhase::kIdle; }

 private:
  enum class SwitchPhase : std::uint8_t { kIdle, kBeforeSwitch, kAfterSwitch };

  void OnSwitchStateGlobal(const CanFrame& frame);
  void OnSwitchStateSelective(LssCs cs, std::uint32_t value);
  void OnIdentifyRemote(LssCs cs, std::uint32_t value);
  void OnIdentifyNonConfigured();
  void OnFastscan(const CanFrame& frame);
  void OnConfigureNodeId(std::uint8_t node_id);
  void OnConfigureBitTiming(std::uint8_t table, std::uint8_t index);
  void OnActivateBitTiming(std::uint16_t delay_ms);
  void OnStoreConfiguration();
  void OnSwitchTimer();
  bool NonConfigured() const {
    return active_node_id_ == kLssUnconfigured && pending_node_id_ == kLssUnconfigured;
  }
  void Reply(LssCs cs, std::uint8_t b1 = 0, std::uint8_t b2 = 0);
  void Reply32(LssCs cs, std::uint32_t value);

  BusPort& port_;
  LssAddress address_;
  Callbacks callbacks_;
  Mode mode_ = Mode::kWaiting;
  std::uint8_t active_node_id_;
  std::uint8_t pending_node_id_;
  std::uint8_t active_bit_timing_;
  std::uint8_t pending_bit_timing_;
  /// Next expected switch-selective cs (40h..43h); 40h always restarts the sequence.
  std::uint8_t selective_next_ = 0;
  /// Next expected identify-remote cs (46h..4Bh); 46h always restarts the sequence.
  std::uint8_t identify_next_ = 0;
  /// Fastscan LSSPos: which address part the next bit check is about (0..3).
  std::uint8_t fastscan_pos_ = 0;
  SwitchPhase switch_phase_ = SwitchPhase::kIdle;
  Duration switch_delay_{};
  Timer switch_timer_;
};

}  // namespace canfleet::canopen
