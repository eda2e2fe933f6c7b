#include "node/canopen/stack/canopen_stack.hpp"

#include <algorithm>

namespace canfleet::canopen {

namespace {

std::unique_ptr<ParameterStore> MakeStore(ObjectDictionary& od, const std::filesystem::path& dir) {
  if (dir.empty()) return nullptr;
  return std::make_unique<ParameterStore>(od, dir);
}

// A node-ID configured by LSS and stored (CiA 305 "store configuration") survives restarts and
// wins over the command line, as on a real device whose ID was set by a master.
std::uint8_t InitialNodeId(StackOptions& options, const ParameterStore* store, bool& bit_timing_stored) {
  if (store) {
    if (auto stored = store->LoadLssConfig()) {
      options.bit_timing_index = stored->second;
      bit_timing_stored = true;
      return stored->first;
    }
  }
  return options.node_id;
}

LssAddress ReadIdentity(const ObjectDictionary& od) {
  return {static_cast<std::uint32_t>(od.GetUnsigned(0x1018, 1)),
          static_cast<std::uint32_t>(od.GetUnsigned(0x1018, 2)),
          static_cast<std::uint32_t>(od.GetUnsigned(0x1018, 3)),
          static_cast<std::uint32_t>(od.GetUnsigned(0x1018, 4))};
}

}  // namespace

CanopenStack::CanopenStack(ObjectDictionary& od, BusPort& port, Scheduler& scheduler, StackOptions options,
                           StackHooks hooks, std::shared_ptr<const ErrorPolicy> policy)
    : od_(od),
      port_(port),
      options_(std::move(options)),
      hooks_(std::move(hooks)),
      policy_(policy ? std::move(policy) : std::make_shared<ErrorPolicy>()),
      store_(MakeStore(od, options_.state_dir)),
      node_id_(InitialNodeId(options_, store_.get(), bit_timing_stored_)),
      nmt_(port, node_id_,
           NmtSlave::Callbacks{[this] { ResetApplication(); }, [this] { ResetCommunication(); },
                               [this](NmtState s) { OnStateChanged(s); }}),
      sdo_(od, port, scheduler, options_.sdo),
      emcy_(od, port, scheduler, options_.emcy),
      sync_(od, port, scheduler, *this),
      pdo_(od, port, scheduler, *this),
      hb_producer_(od, port, scheduler, [this] { return nmt_.State(); }),
      hb_consumer_(od, scheduler, *this),
      guarding_(od, port, scheduler, *this, [this] { return nmt_.State(); }) {
  lss_ = std::make_unique<LssSlave>(port, scheduler, ReadIdentity(od), node_id_, options_.bit_timing_index,
                                    LssSlave::Callbacks{[this](std::uint8_t id) { ApplyNodeId(id); },
                                                        [this](std::uint8_t id, std::uint8_t timing) {
                                                          return store_ && store_->SaveLssConfig(id, timing);
                                                        },
                                                        [this](std::uint8_t timing) {
                                                          SetBitTiming(timing);
                                                          if (hooks_.on_bit_timing)
                                                            hooks_.on_bit_timing(timing);
                                                        }});
  SetBitRateObject(options_.bit_timing_index);
  // Only CiA 305 table-0 indexes are bit rates (UMAX020411A Table 32: 5 is reserved).
  if (options_.bit_rate_object) {
    if (SubObject* sub = od_.Find(options_.bit_rate_object->index, options_.bit_rate_object->sub_index)) {
      sub->AddValidator([](const SubObject&, std::span<const std::uint8_t> data, Origin) {
        const std::uint64_t value = DecodeUnsignedLe(data);
        return value <= 0xFF && BitRateKbit(static_cast<std::uint8_t>(value)) ? SdoAbort::kNone
                                                                              : SdoAbort::kInvalidValue;
      });
    }
  }
  if (!store_) RefuseStorageWithoutStateDir();
  sync_.OnSync([this](std::uint8_t counter) { pdo_.OnSync(counter); });
  port_.OnReceive([this](const CanFrame& frame, BusTime) { OnFrame(frame); });
  port_.OnStateChange([this](const ControllerEvent& event) { OnControllerEvent(event); });
}

CanopenStack::~CanopenStack() {
  port_.OnReceive(nullptr);
  port_.OnStateChange(nullptr);
}

void CanopenStack::Start() {
  ResetApplication();
}

// CiA 301 §7.3.2.2.1 (figure 48): reset application restores the manufacturer and profile areas
// (2000h–FFFFh) to their power-on values (defaults, then stored values), then continues with
// reset communication.
void CanopenStack::ResetApplication() {
  od_.RestoreDefaults(0x2000, 0xFFFF, node_id_);
  ApplyStored(0x2000, 0xFFFF);
  emcy_.ClearAll();
  if (hooks_.on_reset_application) hooks_.on_reset_application();
  ApplyBitRateObject();
  ResetCommunication();
}

// The Axiomatic manuals' 5B50h (UMAX020411A §3.4.110, UMAX181001 §3.4.79, UMAX080311 §2.4 table):
// "could be configured to different baud rates by changing the value in this object", without
// saying when. The product reads it as it reads every parameter: at reset, from what was stored
// (§3.2 1010h: changes not stored "will be lost on the next power cycle"; 1011h: "set valid only
// after the device is reset or power-cycled"). Unlike LSS there is no switch delay: the controller
// starts at the new rate, as after a power cycle.
void CanopenStack::ApplyBitRateObject() {
  if (!options_.bit_rate_object) return;
  const auto [index, sub] = *options_.bit_rate_object;
  if (od_.Find(index, sub) == nullptr) return;
  const std::uint64_t value = od_.GetUnsigned(index, sub);
  if (value > 0xFF || !BitRateKbit(static_cast<std::uint8_t>(value))) return;  // not a table-0 index
  const auto timing = static_cast<std::uint8_t>(value);
  if (timing == options_.bit_timing_index) return;
  SetBitTiming(timing);
  if (hooks_.on_bit_timing) hooks_.on_bit_timing(timing);
}

void CanopenStack::SetBitTiming(std::uint8_t index) {
  options_.bit_timing_index = index;
  lss_->SetBitTiming(index);
  SetBitRateObject(index);
}

void CanopenStack::AdoptBitTiming(std::uint8_t index) {
  SetBitTiming(index);
}

void CanopenStack::SetBitRateObject(std::uint8_t index) {
  if (!options_.bit_rate_object) return;
  SubObject* sub = od_.Find(options_.bit_rate_object->index, options_.bit_rate_object->sub_index);
  if (sub == nullptr) return;
  sub->default_value = EncodeLe(index, FixedSize(sub->type).value_or(1));
  sub->default_adds_node_id = false;
  sub->value = sub->default_value;
}

// Reset communication restores the communication area (1000h–1FFFh) and restarts every
// communication service with the current node-ID, then boots.
void CanopenStack::ResetCommunication() {
  // CiA 305 §3.8.2: a pending node-ID configured by LSS becomes active at reset communication.
  std::uint8_t pending = lss_->PendingNodeId();
  if (pending != node_id_ && (pending == kUnconfiguredNodeId || (pending >= 1 && pending <= 127)))
    node_id_ = pending;
  od_.RestoreDefaults(0x1000, 0x1FFF, node_id_);
  ApplyStored(0x1000, 0x1FFF);
  nmt_.SetNodeId(node_id_);
  sdo_.SetNodeId(node_id_);
  emcy_.SetNodeId(node_id_);
  pdo_.SetNodeId(node_id_);
  hb_producer_.SetNodeId(node_id_);
  guarding_.SetNodeId(node_id_);
  hb_consumer_.Reset();
  guarding_.Reset();
  lss_->SetActiveNodeId(node_id_);
  Boot();
}

void CanopenStack::Boot() {
  hb_producer_.Stop();
  // An unconfigured LSS slave takes part in LSS only: no boot-up, no NMT, no SDO (CiA 305 §3.4).
  if (!Configured()) return;
  nmt_.Boot(options_.start_operational && options_.start_operational());
  hb_producer_.Start();
}

void CanopenStack::ApplyStored(std::uint16_t first, std::uint16_t last) {
  if (!store_) return;
  LoadReport report = store_->ApplyStored(first, last, node_id_);
  if (!report.Quiet() && hooks_.on_storage_issue) hooks_.on_storage_issue(report.ToString());
}

// Without a state directory nothing can be stored: say so instead of accepting "save" silently.
void CanopenStack::RefuseStorageWithoutStateDir() {
  for (std::uint16_t index : {std::uint16_t{0x1010}, std::uint16_t{0x1011}}) {
    Object* object = od_.Find(index);
    if (!object) continue;
    for (auto& [sub_index, sub] : object->subs) {
      if (sub_index == 0) continue;
      sub.AddValidator(
          [](const SubObject&, std::span<const std::uint8_t>, Origin) { return SdoAbort::kCannotTransfer; });
    }
  }
}

void CanopenStack::ApplyNodeId(std::uint8_t node_id) {
  node_id_ = node_id;
  ResetCommunication();
}

std::vector<std::pair<std::uint32_t, Duration>> CanopenStack::PassiveIds() const {
  std::vector<std::pair<std::uint32_t, Duration>> passive;
  if (!Configured()) return passive;
  hb_consumer_.AddPassiveIds(passive);
  // An identifier another service listens to too (an RPDO on 7xxh) is not passive.
  std::vector<std::uint32_t> others;
  LssSlave::AddListenedIds(others);
  NmtSlave::AddListenedIds(others);
  guarding_.AddListenedIds(others);
  sdo_.AddListenedIds(others);
  sync_.AddListenedIds(others);
  pdo_.AddListenedIds(others);
  std::erase_if(passive, [&](const auto& p) { return std::ranges::find(others, p.first) != others.end(); });
  std::sort(passive.begin(), passive.end());
  return passive;
}

std::vector<std::uint32_t> CanopenStack::ListenedIds() const {
  // The same services, in the same order, as OnFrame routes to.
  std::vector<std::uint32_t> ids;
  LssSlave::AddListenedIds(ids);
  if (Configured()) {
    NmtSlave::AddListenedIds(ids);
    guarding_.AddListenedIds(ids);
    hb_consumer_.AddListenedIds(ids);
    sdo_.AddListenedIds(ids);
    sync_.AddListenedIds(ids);
    pdo_.AddListenedIds(ids);
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

void CanopenStack::OnFrame(const CanFrame& frame) {
  // An error frame (a node at another bit rate than its bus sees them instead of traffic) carries
  // an identifier but no message: no service may take it for one (a heartbeat, an LSS request).
  if (frame.error()) return;
  if (lss_->OnFrame(frame)) return;
  if (!Configured()) return;
  if (nmt_.OnFrame(frame)) return;
  // Each service gates itself by NMT state; the stack only routes.
  if (guarding_.OnFrame(frame)) return;
  if (hb_consumer_.OnFrame(frame)) return;
  if (sdo_.OnFrame(frame)) return;
  if (sync_.OnFrame(frame)) return;
  pdo_.OnFrame(frame);
}

void CanopenStack::OnStateChanged(NmtState state) {
  sdo_.SetEnabled(SdoAllowed(state));
  emcy_.SetNmtState(state);
  sync_.SetNmtState(state);
  pdo_.SetNmtState(state);
  if (hooks_.on_state_changed) hooks_.on_state_changed(state);
}

// ISO 11898-1 fault confinement seen from the node: bus-off and error-passive are
// communication errors (EMCY 8140h / 8120h) that clear when the controller is error-active again.
void CanopenStack::OnControllerEvent(const ControllerEvent& event) {
  ControllerState before = controller_.state;
  controller_ = event;
  if (before == event.state) return;
  if (before == ControllerState::kBusOff) {
    emcy_.OnBusOffEnded();  // the 8140h raised at bus-off leaves first
    OnCommError({CommErrorKind::kBusOff}, false);
  }
  if (before == ControllerState::kErrorPassive) OnCommError({CommErrorKind::kErrorPassive}, false);
  if (event.state == ControllerState::kBusOff) OnCommError({CommErrorKind::kBusOff}, true);
  if (event.state == ControllerState::kErrorPassive) OnCommError({CommErrorKind::kErrorPassive}, true);
}

// CiA 301 §7.5.2.32, 1029h error behaviour: 0 = enter pre-operational (only from operational),
// 1 = no change, 2 = enter stopped. Without 1029h a device behaves as for 0.
void CanopenStack::OnCommError(const CommError& error, bool active) {
  if (auto encoding = policy_->Encode(error)) {
    if (active) {
      emcy_.Raise(encoding->entry);
      if (encoding->behaviour_sub != 0) {
        const SubObject* behaviour = od_.Find(0x1029, encoding->behaviour_sub);
        auto reaction = behaviour ? DecodeUnsignedLe(behaviour->value) : 0;
        if (reaction == 0 && nmt_.State() == NmtState::kOperational) nmt_.SetState(NmtState::kPreOperational);
        if (reaction == 2 && nmt_.State() != NmtState::kStopped) nmt_.SetState(NmtState::kStopped);
      }
    } else {
      // Bus-off included: the 8140h EMCY left first (OnBusOffEnded), then this error reset takes
      // its entry out of 1003h, as every manual's 1003h asks (e.g. AX020506 §3.1.4).
      emcy_.Clear(encoding->entry.code, encoding->entry.info);
    }
  }
  if (hooks_.on_comm_error) hooks_.on_comm_error(error, active);
}

}  // namespace canfleet::canopen
