#include "orchestrator/fleet/fault_manager.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "orchestrator/control/fault_kinds.hpp"
#include "orchestrator/control/fault_text.hpp"

namespace canfleet::fleet {

using control::FaultKind;

struct FaultManager::Fault {
  std::uint32_t id = 0;
  control::FaultSpec spec;
  std::string summary;
  std::string state = "active";
  TimePoint started{};
  TimePoint ended{};
  std::string bus;                     ///< where it acts
  std::vector<broker::RuleId> rules;   ///< on `bus`
  std::optional<broker::PortId> port;  ///< controller faults, babbling idiot
  std::uint64_t ended_hits = 0;        ///< hits of rules already removed
  /// The port's babble_frames (babbling idiot) or failed_recoveries (held bus-off) when it began.
  std::uint64_t port_base = 0;
  std::unique_ptr<Timer> expiry;
};

namespace {

constexpr std::uint32_t kStandardMask = 0x7FF;
constexpr std::uint32_t kExtendedMask = 0x1FFFFFFF;

bool Active(const std::string& state) {
  return state == "active";
}

}  // namespace

FaultManager::FaultManager(Context context) : ctx_(std::move(context)) {}

FaultManager::~FaultManager() {
  // Leave the broker clean, quietly: whoever listened to fault events may already be gone.
  ctx_.on_event = nullptr;
  for (auto& fault : faults_)
    if (Active(fault->state)) End(*fault, "cleared");
}

double FaultManager::Seconds(TimePoint t) const {
  return std::chrono::duration<double>(t - ctx_.origin).count();
}

const FleetNode& FaultManager::Node(const std::string& name) const {
  if (name.empty()) throw FaultError("this fault needs --node", true);
  if (const FleetNode* node = ctx_.find_node(name)) return *node;
  // Not a node of the topology: a participant attached under that name (a python-can bus).
  FleetNode participant;
  participant.spec.set_name(name);
  participant.device_label = "participant";
  for (const auto& bus : ctx_.broker.Buses()) {
    if (!ctx_.broker.NewestPortNamed(bus, name)) continue;
    participant.buses.push_back(bus);
    participant.node_ids.push_back(0);
  }
  if (participant.buses.empty())
    throw FaultError(
        ctx_.unknown_node ? ctx_.unknown_node(name) : "no node called '" + name + "' in this fleet", true);
  return participants_[name] = std::move(participant);
}

bool FaultManager::IsParticipant(const FleetNode& node) const {
  return ctx_.find_node(node.name()) == nullptr;
}

broker::PortId FaultManager::PortOf(const std::string& bus, const std::string& node) const {
  const std::optional<broker::PortId> found = ctx_.broker.NewestPortNamed(bus, node);
  if (!found) throw FaultError("node '" + node + "' is not attached to bus " + bus + " right now");
  return *found;
}

std::string FaultManager::BusFor(const control::FaultSpec& spec) const {
  if (!spec.bus().empty()) {
    const auto buses = ctx_.broker.Buses();
    if (std::find(buses.begin(), buses.end(), spec.bus()) == buses.end())
      throw FaultError("no bus called '" + spec.bus() + "'", true);
    if (!spec.node().empty() && Node(spec.node()).PortOn(spec.bus()) < 0)
      throw FaultError("node '" + spec.node() + "' is not on bus " + spec.bus(), true);
    return spec.bus();
  }
  if (!spec.node().empty()) return Node(spec.node()).buses.front();
  const auto buses = ctx_.broker.Buses();
  if (buses.size() == 1) return buses.front();
  throw FaultError("say which bus (--bus)", true);
}

std::vector<broker::PortId> FaultManager::ReceiverPorts(const std::string& bus,
                                                        const control::FaultSpec& spec) const {
  std::vector<broker::PortId> ports;
  for (const auto& name : spec.receivers()) {
    if (Node(name).PortOn(bus) < 0) throw FaultError("receiver '" + name + "' is not on bus " + bus, true);
    ports.push_back(PortOf(bus, name));
  }
  return ports;
}

control::FaultInjected FaultManager::Inject(const control::FaultSpec& spec) {
  if (!spec.label().empty()) {
    for (const auto& f : faults_)
      if (Active(f->state) && f->spec.label() == spec.label())
        throw FaultError("a fault labelled '" + spec.label() + "' is already active");
  }
  auto fault = std::make_unique<Fault>();
  fault->id = next_id_;
  fault->spec = spec;
  fault->started = ctx_.scheduler.Now();
  // What the kind takes and needs (one table for the CLI, the topology and here), once the bus
  // the fault acts on is known: the node's first bus, or the fleet's only bus.
  const control::FaultKindTraits* kind = control::TraitsOf(spec.kind());
  if (kind != nullptr && kind->takes.Has(control::FaultOption::kBus) && spec.bus().empty() &&
      (!spec.node().empty() || ctx_.broker.Buses().size() == 1))
    fault->spec.set_bus(BusFor(spec));
  if (const auto problem = control::CheckFaultSpec(fault->spec, control::FaultSpelling::kCli))
    throw FaultError(problem->reason, true);
  Apply(*fault);  // throws before anything is registered
  if (fault->spec.bus().empty() && !fault->bus.empty()) fault->spec.set_bus(fault->bus);
  fault->summary = control::SummarizeFault(fault->spec);
  ++next_id_;
  Fault& added = *faults_.emplace_back(std::move(fault));

  // A bus-off with automatic recovery is over once the controller has recovered (1408 bit
  // times): an event, like a restart, not a state to clear.
  if (control::IsOneShot(spec)) {
    added.state = "done";
    added.ended = added.started;
  } else if (spec.duration_ms() > 0) {
    added.expiry = std::make_unique<Timer>(ctx_.scheduler, [this, &added] { End(added, "expired"); });
    added.expiry->StartAfter(std::chrono::milliseconds(spec.duration_ms()));
  }
  spdlog::warn("fault {} injected: {}", added.id, added.summary);
  if (ctx_.on_event) ctx_.on_event(StatusOf(added), true);

  control::FaultInjected reply;
  reply.set_fault_id(added.id);
  reply.set_summary(added.summary);
  return reply;
}

void FaultManager::Apply(Fault& fault) {
  switch (fault.spec.kind()) {
    case control::BUS_OFF:
      ApplyBusOff(fault);
      break;
    case control::HEARTBEAT_LOSS:
      ApplyHeartbeatLoss(fault);
      break;
    case control::RPDO_TIMEOUT:
      ApplyRpdoTimeout(fault);
      break;
    case control::DROP:
    case control::DELAY:
    case control::CORRUPT:
    case control::DUPLICATE:
      ApplyFrameFault(fault);
      break;
    case control::PARTITION:
      ApplyPartition(fault);
      break;
    case control::BABBLING_IDIOT:
      ApplyBabblingIdiot(fault);
      break;
    case control::ERROR_PASSIVE:
      ApplyErrorPassive(fault);
      break;
    case control::KILL:
    case control::RESTART:
    case control::POWER_CYCLE:
      ApplyProcessFault(fault);
      break;
    default:
      throw FaultError("say which fault (kind)", true);
  }
}

void FaultManager::ApplyBusOff(Fault& fault) {
  fault.bus = BusFor(fault.spec);
  fault.port = PortOf(fault.bus, Node(fault.spec.node()).name());
  auto& stage = ctx_.broker.Faults(fault.bus);
  if (fault.spec.duration_ms() > 0) {
    // Held: a cause that persists, so every recovery attempt fails until the fault ends.
    fault.port_base = ctx_.broker.Port(*fault.port).failed_recoveries;
    if (!stage.HoldBusOff(*fault.port, true))
      throw FaultError("node '" + fault.spec.node() + "' is already held bus-off");
    return;
  }
  if (!stage.ForceBusOff(*fault.port, fault.spec.manual_recovery()))
    throw FaultError("node '" + fault.spec.node() + "' is already bus-off");
}

void FaultManager::ApplyHeartbeatLoss(Fault& fault) {
  const FleetNode& node = Node(fault.spec.node());
  fault.bus = BusFor(fault.spec);
  const auto node_id = node.node_ids[static_cast<std::size_t>(node.PortOn(fault.bus))];
  if (IsParticipant(node))
    throw FaultError("'" + node.name() +
                     "' is a participant, not a CANopen node: it has no heartbeat to lose");
  broker::FaultRule rule;
  rule.source = PortOf(fault.bus, node.name());
  rule.id = 0x700u + node_id;
  rule.mask = kStandardMask;
  rule.extended = false;
  rule.receivers = ReceiverPorts(fault.bus, fault.spec);
  rule.action = broker::RuleAction::kDrop;
  rule.probability = fault.spec.probability() > 0 ? fault.spec.probability() : 1.0;
  rule.seed = fault.spec.seed() != 0 ? fault.spec.seed() : ctx_.seed != 0 ? ctx_.seed + fault.id : 0;
  if (fault.spec.count() > 0) rule.count = fault.spec.count();
  fault.rules.push_back(ctx_.broker.Faults(fault.bus).Add(rule));
}

void FaultManager::ApplyRpdoTimeout(Fault& fault) {
  const FleetNode& node = Node(fault.spec.node());
  fault.bus = BusFor(fault.spec);
  broker::FaultRule rule;
  rule.id = fault.spec.cob_id();
  rule.mask = fault.spec.extended() ? kExtendedMask : kStandardMask;
  rule.extended = fault.spec.extended();
  rule.receivers = {PortOf(fault.bus, node.name())};
  rule.action = broker::RuleAction::kDrop;
  fault.rules.push_back(ctx_.broker.Faults(fault.bus).Add(rule));
}

void FaultManager::ApplyFrameFault(Fault& fault) {
  const auto& spec = fault.spec;
  fault.bus = BusFor(spec);
  broker::FaultRule rule;
  if (!spec.node().empty()) rule.source = PortOf(fault.bus, Node(spec.node()).name());
  if (spec.has_cob_id()) {
    rule.id = spec.cob_id();
    rule.mask = spec.has_mask() ? spec.mask() : (spec.extended() ? kExtendedMask : kStandardMask);
    rule.extended = spec.extended();
  } else if (spec.extended()) {
    rule.extended = true;  // "all extended frames"
  }
  rule.receivers = ReceiverPorts(fault.bus, spec);
  switch (spec.kind()) {
    case control::DROP:
      rule.action = broker::RuleAction::kDrop;
      break;
    case control::DELAY:
      rule.action = broker::RuleAction::kDelay;
      rule.delay = std::chrono::milliseconds(spec.delay_ms());
      rule.jitter = std::chrono::milliseconds(spec.jitter_ms());
      break;
    case control::CORRUPT:
      rule.action = broker::RuleAction::kCorrupt;
      break;
    default:
      rule.action = broker::RuleAction::kDuplicate;
      break;
  }
  rule.probability = spec.probability() > 0 ? spec.probability() : 1.0;
  rule.seed = spec.seed() != 0 ? spec.seed() : ctx_.seed != 0 ? ctx_.seed + fault.id : 0;
  if (spec.count() > 0) rule.count = spec.count();
  try {
    fault.rules.push_back(ctx_.broker.Faults(fault.bus).Add(rule));
  } catch (const std::invalid_argument& e) {
    throw FaultError(e.what());
  }
}

void FaultManager::ApplyPartition(Fault& fault) {
  const auto& spec = fault.spec;
  fault.bus = BusFor(spec);
  // Resolve everything first, so a bad name leaves no half-applied partition.
  std::vector<std::vector<broker::PortId>> groups;
  for (const auto& group : spec.groups()) {
    auto& ports = groups.emplace_back();
    for (const auto& name : group.nodes()) {
      if (Node(name).PortOn(fault.bus) < 0)
        throw FaultError("node '" + name + "' is not on bus " + fault.bus, true);
      ports.push_back(PortOf(fault.bus, name));
    }
  }
  auto& stage = ctx_.broker.Faults(fault.bus);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    std::vector<broker::PortId> others;
    for (std::size_t o = 0; o < groups.size(); ++o)
      if (o != g) others.insert(others.end(), groups[o].begin(), groups[o].end());
    for (const auto port : groups[g]) {
      broker::FaultRule rule;
      rule.source = port;
      rule.receivers = others;
      rule.action = broker::RuleAction::kDrop;
      fault.rules.push_back(stage.Add(rule));
    }
  }
}

void FaultManager::ApplyBabblingIdiot(Fault& fault) {
  const auto& spec = fault.spec;
  fault.bus = BusFor(spec);
  fault.port = PortOf(fault.bus, Node(spec.node()).name());
  const std::uint32_t id = spec.has_cob_id() ? spec.cob_id() : 0x001;
  CanFrame frame = CanFrame::Data(id, {0xBA, 0xBB, 0x1E, 0xBA, 0xBB, 0x1E, 0xBA, 0xBB});
  if (spec.extended()) frame.flags |= CanFrame::kExtended;
  if (!frame.valid()) throw FaultError("babbling-idiot: identifier out of range", true);
  // The node's own controller floods the bus: the frame is offered in every arbitration ahead of
  // the node's queue, at the bus's full rate, as by a babbling controller.
  try {
    ctx_.broker.Faults(fault.bus).StartBabbling(*fault.port, frame);
    fault.port_base = ctx_.broker.Port(*fault.port).babble_frames;
  } catch (const std::invalid_argument& e) {
    throw FaultError(std::string("babbling-idiot: ") + e.what());
  }
}

void FaultManager::ApplyErrorPassive(Fault& fault) {
  fault.bus = BusFor(fault.spec);
  fault.port = PortOf(fault.bus, Node(fault.spec.node()).name());
  ctx_.broker.Faults(fault.bus).HoldErrorPassive(*fault.port, true);
}

void FaultManager::ApplyProcessFault(Fault& fault) {
  const FleetNode& node = Node(fault.spec.node());
  if (IsParticipant(node))
    throw FaultError("'" + node.name() +
                     "' is a participant attached by name, not a node process of this fleet");
  if (node.external() || !ctx_.supervisor.Has(node.name()))
    throw FaultError("node '" + node.name() + "' runs elsewhere (external): the orchestrator cannot " +
                     "kill or restart its process");
  fault.bus = node.buses.front();
  switch (fault.spec.kind()) {
    case control::KILL:
      ctx_.supervisor.Kill(node.name());
      break;
    case control::RESTART:
      ctx_.supervisor.Restart(node.name(), false);
      break;
    default:
      ctx_.supervisor.Restart(node.name(), true);
      break;
  }
}

std::size_t FaultManager::Clear(const control::FaultClear& which) {
  std::vector<Fault*> targets;
  for (auto& f : faults_) {
    if (!Active(f->state)) continue;
    if (which.fault_id() != 0 ? f->id == which.fault_id()
                              : (which.label().empty() || f->spec.label() == which.label()))
      targets.push_back(f.get());
  }
  if (targets.empty() && (which.fault_id() != 0 || !which.label().empty())) {
    throw FaultError(which.fault_id() != 0 ? "no active fault " + std::to_string(which.fault_id())
                                           : "no active fault labelled '" + which.label() + "'");
  }
  for (Fault* f : targets)
    End(*f, "cleared");
  return targets.size();
}

std::uint64_t FaultManager::Hits(const Fault& fault) const {
  std::uint64_t hits = fault.ended_hits;
  if (!Active(fault.state)) return hits;
  const bool held_bus_off = fault.spec.kind() == control::BUS_OFF && fault.spec.duration_ms() > 0;
  if ((fault.spec.kind() == control::BABBLING_IDIOT || held_bus_off) && fault.port) {
    try {
      const broker::PortStats port = ctx_.broker.Port(*fault.port);
      hits += (held_bus_off ? port.failed_recoveries : port.babble_frames) - fault.port_base;
    } catch (const std::invalid_argument&) {
      // detached: its count went with it
    }
  }
  if (fault.rules.empty()) return hits;
  const auto live = ctx_.broker.Faults(fault.bus).List();
  for (const auto rule : fault.rules) {
    auto it = std::find_if(live.begin(), live.end(), [rule](const auto& r) { return r.id == rule; });
    // A rule the broker no longer lists was used up: it fired `count` times.
    hits += it != live.end() ? it->hits : fault.spec.count();
  }
  return hits;
}

void FaultManager::Sweep() {
  // Count-limited rules end inside the broker; the fault ends with its last rule.
  for (auto& fault : faults_) {
    if (!Active(fault->state) || fault->rules.empty() || fault->spec.count() == 0) continue;
    const auto live = ctx_.broker.Faults(fault->bus).List();
    const bool any = std::any_of(fault->rules.begin(), fault->rules.end(), [&](broker::RuleId id) {
      return std::any_of(live.begin(), live.end(), [id](const auto& r) { return r.id == id; });
    });
    if (!any) End(*fault, "expired");
  }
}

void FaultManager::End(Fault& fault, const char* state) {
  if (!Active(fault.state)) return;
  fault.ended_hits = Hits(fault);
  if (fault.expiry) fault.expiry->Cancel();
  auto& stage = ctx_.broker.Faults(fault.bus.empty() ? ctx_.broker.Buses().front() : fault.bus);
  for (const auto rule : fault.rules)
    stage.Remove(rule);  // false when a count-limited rule already expired
  fault.rules.clear();
  try {
    switch (fault.spec.kind()) {
      case control::BUS_OFF:
        if (!fault.port) break;
        if (fault.spec.duration_ms() > 0)
          // The cause is gone: the next recovery attempt succeeds (on a bus that recovers on
          // command only, the port then waits for one, as after any bus-off).
          stage.HoldBusOff(*fault.port, false);
        else
          // Recovery on command; an automatically recovered port is not bus-off any more.
          ctx_.broker.RecoverBusOff(*fault.port);
        break;
      case control::ERROR_PASSIVE:
        if (fault.port) stage.HoldErrorPassive(*fault.port, false);
        break;
      case control::BABBLING_IDIOT:
        if (fault.port) stage.StopBabbling(*fault.port);
        break;
      case control::KILL:
        ctx_.supervisor.Start(fault.spec.node());
        break;
      default:
        break;
    }
  } catch (const std::invalid_argument&) {
    // The port detached meanwhile (the node restarted): nothing left to undo on it.
  }
  fault.state = state;
  fault.ended = ctx_.scheduler.Now();
  spdlog::warn("fault {} {}: {}", fault.id, state, fault.summary);
  if (ctx_.on_event) ctx_.on_event(StatusOf(fault), false);
}

control::FaultStatus FaultManager::StatusOf(const Fault& fault) const {
  control::FaultStatus status;
  status.set_fault_id(fault.id);
  *status.mutable_spec() = fault.spec;
  status.set_summary(fault.summary);
  status.set_state(fault.state);
  status.set_started_s(Seconds(fault.started));
  status.set_ended_s(Active(fault.state) ? 0.0 : Seconds(fault.ended));
  status.set_hits(Hits(fault));
  return status;
}

std::vector<control::FaultStatus> FaultManager::List(bool include_ended) {
  Sweep();
  std::vector<control::FaultStatus> list;
  for (const auto& f : faults_)
    if (Active(f->state)) list.push_back(StatusOf(*f));
  if (include_ended)
    for (const auto& f : faults_)
      if (!Active(f->state)) list.push_back(StatusOf(*f));
  return list;
}

}  // namespace canfleet::fleet
