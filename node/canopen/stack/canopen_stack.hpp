#pragma once
/// @file A complete CiA 301/305 slave: composes the services on one BusPort and one Scheduler,
/// dispatches received frames, gates services by NMT state (CiA 301 §7.3.2.2 table 51), runs the
/// reset sequence, turns controller events and service errors into EMCY/1003h entries, and applies
/// the 1029h error behaviour. Device code owns the OD contents and hooks into it.

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>

#include "bus/bus_port.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/common/comm_error.hpp"
#include "node/canopen/common/nmt_state.hpp"
#include "node/canopen/emcy/emcy.hpp"
#include "node/canopen/guarding/node_guarding.hpp"
#include "node/canopen/heartbeat/heartbeat_consumer.hpp"
#include "node/canopen/heartbeat/heartbeat_producer.hpp"
#include "node/canopen/lss/lss_slave.hpp"
#include "node/canopen/nmt/nmt_slave.hpp"
#include "node/canopen/od/object_dictionary.hpp"
#include "node/canopen/pdo/pdo_service.hpp"
#include "node/canopen/sdo/sdo_server.hpp"
#include "node/canopen/stack/error_policy.hpp"
#include "node/canopen/storage/parameter_store.hpp"
#include "node/canopen/sync/sync_service.hpp"

namespace canfleet::canopen {

/// The node-ID of an LSS slave that has none yet (CiA 305 §3.4).
inline constexpr std::uint8_t kUnconfiguredNodeId = 0xFF;

/// A device object that holds the port's bit rate as a CiA 305 table-0 index (the Axiomatic
/// manuals' 5B50h "Change Baud Rate", Table 32 of UMAX020411A: 0 = 1 Mbit/s ... 4 = 125 kbit/s ...
/// 8 = 10 kbit/s). See StackOptions::bit_rate_object.
struct BitRateObject {
  std::uint16_t index = 0;
  std::uint8_t sub_index = 0;
};

struct StackOptions {
  /// 1..127, or kUnconfiguredNodeId: the node then runs only LSS until a master assigns an ID.
  std::uint8_t node_id = kUnconfiguredNodeId;
  /// LSS bit timing index (CiA 305 table 0: 0 = 1 Mbit/s ... 4 = 125 kbit/s).
  std::uint8_t bit_timing_index = 4;
  /// The device's bit-rate object, if it has one. Its value is the bit rate the port runs at
  /// from the next reset application (power-on, NMT reset node) on: after the stored parameters
  /// are applied, a value that differs from the active index switches the port (on_bit_timing).
  /// A written value therefore takes effect at the next reset only if it was stored (1010h): the
  /// reset restores the manufacturer area to its stored values, as every other object's (the
  /// manuals' 1010h: unsaved changes are lost). Its default is the active bit timing (the factory
  /// or LSS-stored rate, then each LSS activation), so an unstored object follows LSS.
  std::optional<BitRateObject> bit_rate_object;
  /// Per-node folder for stored parameters (1010h/1011h) and LSS configuration; empty = none.
  std::filesystem::path state_dir;
  SdoServerOptions sdo;
  EmcyOptions emcy;
  /// Boot straight to Operational (e.g. the Quad's 5555h "Start in Operational Mode").
  std::function<bool()> start_operational;
};

/// Device hooks into the stack's life cycle.
struct StackHooks {
  /// Reset application (NMT reset node, power-on), after parameters were restored.
  std::function<void()> on_reset_application;
  /// Every NMT state change, after the services were gated.
  std::function<void(NmtState)> on_state_changed;
  /// Every communication error as it appears (true) and disappears (false), after the policy ran.
  std::function<void(const CommError&, bool)> on_comm_error;
  /// Stored parameters that could not be applied (corrupt file, missing object...), and a save all
  /// or restore all that a kill interrupted and the store completed or discarded: one line each.
  std::function<void(const std::string&)> on_storage_issue;
  /// The port should switch to this CiA 305 table-0 index: LSS "activate bit timing" completed,
  /// or the bit-rate object (StackOptions::bit_rate_object) holds another rate at reset.
  std::function<void(std::uint8_t bit_timing_index)> on_bit_timing;
};

class CanopenStack final : private CommErrorSink {
 public:
  /// @param od the device's dictionary; must outlive the stack. @param policy may be null (CiA 301 codes).
  CanopenStack(ObjectDictionary& od, BusPort& port, Scheduler& scheduler, StackOptions options,
               StackHooks hooks = {}, std::shared_ptr<const ErrorPolicy> policy = nullptr);
  ~CanopenStack() override;

  /// Power-on: restores defaults and stored parameters, then boots (boot-up frame, pre-operational).
  void Start();

  NmtState State() const { return nmt_.State(); }
  std::uint8_t NodeId() const { return node_id_; }
  /// The CiA 305 table-0 index the port runs at.
  std::uint8_t BitTimingIndex() const { return options_.bit_timing_index; }
  /// Whether that index came from a stored LSS configuration (CiA 305 store configuration) rather
  /// than from StackOptions.
  bool BitTimingStored() const { return bit_timing_stored_; }
  /// Takes `index` as the port's bit timing before Start(), without on_bit_timing (the port already
  /// runs at it): e.g. a node whose rate nobody configured, commissioned for the bus it is on.
  void AdoptBitTiming(std::uint8_t index);
  ObjectDictionary& od() { return od_; }
  Emcy& emcy() { return emcy_; }
  PdoService& pdo() { return pdo_; }
  SyncService& sync() { return sync_; }
  HeartbeatConsumer& heartbeat_consumer() { return hb_consumer_; }
  LssSlave& lss() { return *lss_; }
  ParameterStore* store() { return store_.get(); }
  /// The last controller event (state, TEC, REC) reported by the bus port.
  const ControllerEvent& Controller() const { return controller_; }
  /// The 11-bit identifiers the stack's configuration makes it listen to, sorted: a frame with
  /// another 11-bit identifier would change nothing in any NMT state (an acceptance filter;
  /// orchestrator/broker/README.md "Acceptance filters"). Extended frames are not covered: they
  /// always reach the stack. Follows the LSS configuration and the communication objects, not the
  /// NMT state: a filter changes only with a write, an LSS command or a reset, each of which the
  /// node answers, so in real time the new filter reaches the broker with that answer.
  std::vector<std::uint32_t> ListenedIds() const;
  /// Of ListenedIds, the heartbeats answered with nothing at once, each with the time before
  /// which nothing follows from it (HeartbeatConsumer::AddPassiveIds).
  std::vector<std::pair<std::uint32_t, Duration>> PassiveIds() const;

  /// Local NMT transition (device logic, tests). Same effect as the NMT command.
  void SetState(NmtState state) { nmt_.SetState(state); }

 private:
  void OnFrame(const CanFrame& frame);
  void OnControllerEvent(const ControllerEvent& event);
  void OnCommError(const CommError& error, bool active) override;
  void OnStateChanged(NmtState state);
  void ResetApplication();
  void ResetCommunication();
  void Boot();
  void ApplyNodeId(std::uint8_t node_id);
  void ApplyStored(std::uint16_t first, std::uint16_t last);
  /// Reset application: the bit-rate object's value, if it differs from the active index, becomes
  /// the port's rate.
  void ApplyBitRateObject();
  /// Sets the bit-rate object's default and value to `index`.
  void SetBitRateObject(std::uint8_t index);
  void SetBitTiming(std::uint8_t index);
  void RefuseStorageWithoutStateDir();
  bool Configured() const { return node_id_ >= 1 && node_id_ <= 127; }

  // Declaration order is construction order: the store is read before the node-ID is chosen.
  ObjectDictionary& od_;
  BusPort& port_;
  StackOptions options_;
  StackHooks hooks_;
  std::shared_ptr<const ErrorPolicy> policy_;
  std::unique_ptr<ParameterStore> store_;
  bool bit_timing_stored_ = false;
  std::uint8_t node_id_;
  ControllerEvent controller_;

  NmtSlave nmt_;
  SdoServer sdo_;
  Emcy emcy_;
  SyncService sync_;
  PdoService pdo_;
  HeartbeatProducer hb_producer_;
  HeartbeatConsumer hb_consumer_;
  NodeGuarding guarding_;
  std::unique_ptr<LssSlave> lss_;
};

}  // namespace canfleet::canopen
