#include "orchestrator/topology/node_checks.hpp"

#include "vocabulary/nearest_names.hpp"

#include <mutex>
#include <optional>
#include <set>
#include <system_error>
#include <utility>
#include <vector>

#include "node/canopen/eds/eds_reader.hpp"
#include "node/devices/eds_dictionary.hpp"
#include "orchestrator/control/sdo_value.hpp"
#include "orchestrator/topology/port_numbering.hpp"
#include "vocabulary/nearest_names.hpp"

namespace canfleet::topology::detail {

namespace {

constexpr int kMaxHeartbeatConsumers = 127;

// Which node_id entry port `port` uses: the only one, or its own.
int IdIndex(const Node& node, std::size_t port) {
  return node.node_id_size() == 1 ? 0 : static_cast<int>(port);
}

void CheckFile(const Scope& s, std::string_view field, const std::string& given, const fs::path& resolved) {
  std::error_code ec;
  const fs::file_status status = fs::status(resolved, ec);
  if (ec || !fs::exists(status))
    s.Fail(field, Quote(given) + ": no such file (looked for " + resolved.string() + ")");
  if (!fs::is_regular_file(status))
    s.Fail(field, Quote(given) + ": not a regular file (" + resolved.string() + ")");
}

void CheckNodeIds(const Scope& s, const Node& node, NodeFacts& facts) {
  if (node.node_id_size() == 0)
    s.FailHere("node " + node.name() + " needs node_id (1..127, or 255 for an LSS slave)");
  if (node.node_id_size() != 1 && static_cast<std::size_t>(node.node_id_size()) != facts.ports)
    s.Fail("node_id", 0,
           "give one node-ID, or one per port (" + facts.kind + " has " + PortsText(facts.ports) + "); " +
               std::to_string(node.node_id_size()) + " given");
  for (int k = 0; k < node.node_id_size(); ++k) {
    const std::uint32_t id = node.node_id(k);
    if ((id < 1 || id > 127) && id != kUnconfiguredNodeId)
      s.Fail("node_id", k,
             std::to_string(id) + " is not a node-ID (1..127, or 255 for an unconfigured LSS slave)");
  }
  for (std::size_t p = 0; p < facts.ports; ++p) {
    facts.ids.push_back(node.node_id(IdIndex(node, p)));
    facts.id_locs.push_back(s.At("node_id", IdIndex(node, p)));
  }
}

// The dictionaries (one per port) of a node's device, built once per process for each variant
// and EDS file (a fleet of a hundred Quads or I/O modules loads in one go): a variant's own EDS
// is compiled in; an EDS file is known by its path, size and modification time, so an edited
// file is read again.
std::shared_ptr<const std::vector<canopen::ObjectDictionary>> Dictionaries(const devices::DeviceInfo* variant,
                                                                           std::size_t ports,
                                                                           const fs::path& eds) {
  static std::mutex mutex;
  static std::map<std::string, std::shared_ptr<const std::vector<canopen::ObjectDictionary>>> built;
  constexpr std::size_t kMaxBuilt = 64;
  std::string key = variant ? std::string(variant->name) : std::string();
  if (!eds.empty()) {
    std::error_code size_error, time_error;
    const auto size = fs::file_size(eds, size_error);
    const auto time = fs::last_write_time(eds, time_error);
    if (size_error || time_error)
      key.clear();  // not cached: Build says what is wrong
    else
      key += "\n" + eds.string() + "\n" + std::to_string(size) + "\n" +
             std::to_string(time.time_since_epoch().count());
  }
  if (!key.empty()) {
    const std::lock_guard lock(mutex);
    if (const auto it = built.find(key); it != built.end()) return it->second;
  }
  auto dictionaries = std::make_shared<std::vector<canopen::ObjectDictionary>>(ports);
  for (std::size_t p = 0; p < ports; ++p)
    (*dictionaries)[p] =
        variant ? devices::VariantDictionary(*variant, eds) : devices::DictionaryFromEdsFile(eds);
  if (!key.empty()) {
    const std::lock_guard lock(mutex);
    if (built.size() >= kMaxBuilt) built.clear();
    built.emplace(key, dictionaries);
  }
  return dictionaries;
}

void CheckTimeout(const Scope& cs, const HeartbeatConsumer& c) {
  if (c.timeout_ms() == 0)
    cs.Fail("timeout_ms", "required, > 0 (ms without a heartbeat before the loss is reported)");
  if (c.timeout_ms() > 0xFFFF)
    cs.Fail("timeout_ms", std::to_string(c.timeout_ms()) + " does not fit 1016h (at most 65535 ms)");
}

}  // namespace

void NodeChecks::CheckNodes(const Scope& root) {
  // (bus, node-ID) -> index into facts_.nodes and the port
  std::map<std::pair<std::string, std::uint32_t>, std::pair<std::size_t, std::size_t>> used_ids;
  std::map<fs::path, std::size_t> state_dirs;
  for (int i = 0; i < facts_.spec.node_size(); ++i) {
    const Node& node = facts_.spec.node(i);
    const Scope s = root.Child("node", node, i);
    NodeFacts facts;
    facts.index = i;
    facts.name = node.name();
    facts.loc = s.loc();

    if (node.name().empty()) s.Fail("name", "required: the node's name (\"quad-5\")");
    if (std::string problem = NameProblem(node.name()); !problem.empty()) s.Fail("name", problem);
    if (const NodeFacts* other = facts_.FindNode(node.name()))
      s.Fail("name", "node " + node.name() + " is already defined (node[" + std::to_string(other->index) +
                         "], " + LineRef(other->loc) + ")");

    CheckDevice(s, node, facts);
    CheckBusesOfNode(s, node, facts);
    CheckNodeIds(s, node, facts);
    for (std::size_t p = 0; p < facts.ports; ++p) {
      const auto key = std::make_pair(facts.buses[p], facts.ids[p]);
      if (facts.ids[p] == kUnconfiguredNodeId) continue;  // LSS slaves waiting for an ID may share 255
      const auto [it, fresh] = used_ids.emplace(key, std::make_pair(facts_.nodes.size(), p));
      if (!fresh) {
        const auto [other_node, other_port] = it->second;
        const NodeFacts& other =
            other_node < facts_.nodes.size() ? facts_.nodes[other_node] : facts;  // or its own port
        s.Fail("node_id", IdIndex(node, p),
               node.name() + " has node-ID " + std::to_string(facts.ids[p]) + " on bus " + facts.buses[p] +
                   ", already used by node " + other.name + " (" + LineRef(other.id_locs[other_port]) + ")");
      }
    }
    CheckUnconfiguredSerials(s, node, facts);

    facts.state_dir = node.state_dir().empty() ? (facts_.state_root / node.name()).lexically_normal()
                                               : facts_.Resolve(node.state_dir());
    const auto [dir, fresh_dir] = state_dirs.emplace(facts.state_dir, facts_.nodes.size());
    if (!fresh_dir)
      s.Fail("state_dir", "folder " + facts.state_dir.string() + " is already the state folder of node " +
                              facts_.nodes[dir->second].name);

    CheckIo(s, node, facts);
    for (int k = 0; k < node.sdo_size(); ++k) {
      const SdoWrite& w = node.sdo(k);
      const Scope ws = s.Child("sdo", w, k);
      CheckSdo(ws, facts, w.index(), w.subindex(), w.type(), w.value(), w.port(), PortFieldName(w));
    }
    if (node.heartbeat().producer_ms() > 0xFFFF)
      s.Child("heartbeat", node.heartbeat())
          .Fail("producer_ms",
                std::to_string(node.heartbeat().producer_ms()) + " does not fit 1017h (at most 65535 ms)");
    facts.producer_ms = node.heartbeat().producer_ms();

    const Restart& restart = node.restart();
    const Scope rs = s.Child("restart", restart);
    if (!Restart::Policy_IsValid(restart.policy()))
      rs.Fail("policy", "unknown policy " + std::to_string(restart.policy()));
    if (node.external() && restart.policy() != Restart::NEVER)
      rs.Fail("policy",
              "node " + node.name() + " is external (started elsewhere): it cannot be restarted from here");

    static const std::set<std::string, std::less<>> kLevels = {"trace", "debug",    "info", "warn",
                                                               "error", "critical", "off"};
    if (!node.log_level().empty() && !kLevels.contains(node.log_level()))
      s.Fail("log_level", Quote(node.log_level()) +
                              " is not a log level (trace, debug, info, warn, error, critical, off)");

    facts_.nodes.push_back(std::move(facts));
  }
}

void NodeChecks::CheckDevice(const Scope& s, const Node& node, NodeFacts& facts) {
  if (node.device().empty() && node.eds().empty())
    s.FailHere("node " + node.name() + " needs device (a variant: " + devices::KnownDeviceNames() +
               ") or eds (an EDS file for a generic node)");
  if (!node.eds().empty()) {
    facts.eds = facts_.Resolve(node.eds());
    CheckFile(s, "eds", node.eds(), facts.eds);
  }
  if (!node.dcf().empty()) {
    facts.dcf = facts_.Resolve(node.dcf());
    CheckFile(s, "dcf", node.dcf(), facts.dcf);
    try {
      (void)canopen::ReadEds(facts.dcf);
    } catch (const std::exception& e) {
      s.Fail("dcf", e.what());
    }
  }
  if (!node.device().empty()) {
    const devices::DeviceInfo* info = devices::FindDevice(node.device());
    if (info == nullptr) s.Fail("device", devices::UnknownDevice(node.device()));
    facts.ports = info->ports;
    facts.kind = std::string(info->name);
    facts.variant = info;
  } else {
    facts.ports = 1;
    facts.kind = "generic node (" + facts.eds.filename().string() + ")";
  }
  // The catalog's signals and dictionaries check io and sdo; no device is created for that.
  try {
    std::unique_ptr<devices::SimulatedIo>& io = signals_[node.device()];
    if (!io)
      io = facts.variant ? devices::SignalsOf(*facts.variant) : std::make_unique<devices::SimulatedIo>();
    facts.io = io.get();
    facts.dictionaries = Dictionaries(facts.variant, facts.ports, facts.eds);
  } catch (const std::exception& e) {
    s.Fail(node.eds().empty() ? "device" : "eds", e.what());
  }
}

void NodeChecks::CheckBusesOfNode(const Scope& s, const Node& node, NodeFacts& facts) {
  if (node.bus_size() == 0)
    s.FailHere("node " + node.name() + " needs bus: " + PortsText(facts.ports) + ", so " +
               std::to_string(facts.ports) + " bus name(s) (" + facts_.BusNames() + ")");
  if (static_cast<std::size_t>(node.bus_size()) != facts.ports)
    s.Fail("bus", 0,
           facts.kind + " has " + PortsText(facts.ports) + ", so node " + node.name() + " needs " +
               std::to_string(facts.ports) + (facts.ports == 1 ? " bus" : " buses") + "; " +
               std::to_string(node.bus_size()) + " given");
  for (int b = 0; b < node.bus_size(); ++b) {
    if (!facts_.buses.contains(node.bus(b)))
      s.Fail("bus", b,
             "unknown bus " + Quote(node.bus(b)) + " (the topology's buses: " + facts_.BusNames() + ")");
    facts.buses.push_back(node.bus(b));
  }
}

void NodeChecks::CheckUnconfiguredSerials(const Scope& s, const Node& node, const NodeFacts& facts) const {
  for (std::size_t p = 0; p < facts.ports; ++p) {
    if (facts.ids[p] != kUnconfiguredNodeId) continue;
    for (const NodeFacts& other : facts_.nodes) {
      const auto other_id = other.IdOn(facts.buses[p]);
      if (!other_id || *other_id != kUnconfiguredNodeId) continue;
      const Node& o = facts_.spec.node(other.index);
      if (o.serial() == node.serial())
        s.Fail("serial", node.name() + " and " + other.name + " are both unconfigured (node-ID 255) on bus " +
                             facts.buses[p] + " with serial " + std::to_string(node.serial()) +
                             ": LSS tells them apart by serial, give each its own");
    }
  }
}

void NodeChecks::CheckIo(const Scope& s, const Node& node, NodeFacts& facts) {
  // Map entries in the order the file gives them (reflection keeps the parsed order), so a
  // problem names the right line; a key given twice would silently keep only the last.
  const pb::Reflection* reflection = node.GetReflection();
  const pb::FieldDescriptor* io = node.GetDescriptor()->FindFieldByName("io");
  const int count = reflection->FieldSize(node, io);
  std::map<std::string, int> seen;
  for (int k = 0; k < count; ++k) {
    const pb::Message& entry = reflection->GetRepeatedMessage(node, io, k);
    const pb::FieldDescriptor* key_fd = entry.GetDescriptor()->FindFieldByName("key");
    const pb::FieldDescriptor* value_fd = entry.GetDescriptor()->FindFieldByName("value");
    const std::string key = entry.GetReflection()->GetString(entry, key_fd);
    const std::string value = entry.GetReflection()->GetString(entry, value_fd);
    const Scope es = s.Child("io", entry, k);
    const auto [it, fresh] = seen.emplace(key, k);
    if (!fresh) es.Fail("key", Quote(key) + " is already set by io[" + std::to_string(it->second) + "]");
    CheckIoSet(es, "key", "value", facts, key, value);
  }
}

void NodeChecks::CheckHeartbeats(const Scope& root) {
  for (NodeFacts& facts : facts_.nodes) {
    const Node& node = facts_.spec.node(facts.index);
    const Scope s = root.Child("node", node, facts.index).Child("heartbeat", node.heartbeat());
    const Heartbeat& hb = node.heartbeat();
    if (hb.consumer_size() > kMaxHeartbeatConsumers)
      s.Fail("consumer", kMaxHeartbeatConsumers, "at most 127 heartbeat consumers (1016h sub 1..127)");
    const canopen::Object* entries = facts.dictionaries->front().Find(0x1016);
    const int capacity =
        entries == nullptr ? 0 : static_cast<int>(entries->subs.size()) - (entries->subs.contains(0) ? 1 : 0);
    if (hb.consumer_size() > capacity)
      s.Fail("consumer", capacity,
             facts.kind + " has " + std::to_string(capacity) + " heartbeat consumer entries (1016h); " +
                 std::to_string(hb.consumer_size()) + " given");
    std::map<std::uint32_t, int> consumed;
    for (int k = 0; k < hb.consumer_size(); ++k) {
      const HeartbeatConsumer& c = hb.consumer(k);
      const Scope cs = s.Child("consumer", c, k);
      std::uint32_t id = c.node_id();
      if (!c.node().empty()) {
        const NodeFacts* target = facts_.FindNode(c.node());
        if (target == nullptr) cs.Fail("node", "unknown node " + Quote(c.node()));
        if (target == &facts) cs.Fail("node", node.name() + " cannot consume its own heartbeat");
        std::optional<std::uint32_t> target_id;
        for (const std::string& bus : facts.buses) {
          if ((target_id = target->IdOn(bus))) break;
        }
        if (!target_id) cs.Fail("node", node.name() + " and " + target->name + " share no bus");
        if (*target_id == kUnconfiguredNodeId)
          cs.Fail("node", target->name + " has no node-ID yet (255): its heartbeat cannot be consumed");
        if (c.node_id() != 0 && c.node_id() != *target_id)
          cs.Fail("node_id", "node_id " + std::to_string(c.node_id()) + " is not " + target->name +
                                 "'s node-ID (" + std::to_string(*target_id) + ")");
        id = *target_id;
        CheckTimeout(cs, c);
        if (target->producer_ms > 0 && c.timeout_ms() <= target->producer_ms)
          cs.Fail("timeout_ms", std::to_string(c.timeout_ms()) + " ms is not longer than " + target->name +
                                    "'s heartbeat period (" + std::to_string(target->producer_ms) + " ms)");
      } else if (c.node_id() == 0) {
        cs.FailHere("give node (a node of the topology) or node_id (1..127)");
      } else if (c.node_id() > 127) {
        cs.Fail("node_id", std::to_string(c.node_id()) + " is not a node-ID (1..127)");
      }
      CheckTimeout(cs, c);
      const auto [it, fresh] = consumed.emplace(id, k);
      if (!fresh)
        cs.FailHere("node-ID " + std::to_string(id) + " is already consumed by consumer[" +
                    std::to_string(it->second) + "] (CiA 301 allows one entry per producer)");
      facts_.consumer_ids[{facts.index, k}] = id;
    }
  }
}

void CheckIoSet(const Scope& s, std::string_view name_field, std::string_view value_field,
                const NodeFacts& facts, const std::string& name, const std::string& value) {
  if (!LooksLikeSignalName(name))
    s.Fail(name_field, Quote(name) + " is not a signal name (CHANNEL.quantity, e.g. IN1.voltage_mV)");
  if (value.empty()) s.Fail(value_field, "required: the value to set " + name + " to");
  devices::SimulatedIo& io = *facts.io;
  const devices::IoName resolved = ResolveSignal(s, name_field, facts, name, true);
  if (resolved.signal->direction() != devices::IoDirection::kInput)
    s.Fail(name_field, name + " is an output of " + facts.kind + "; only inputs can be set");
  const devices::IoStatus status = io.SetText(name, value);
  if (!status.ok()) s.Fail(value_field, status.error);
}

devices::IoName ResolveSignal(const Scope& s, std::string_view name_field, const NodeFacts& facts,
                              const std::string& name, bool inputs_only) {
  const devices::SimulatedIo& io = *facts.io;
  if (io.Signals().empty())
    s.Fail(name_field, "node " + facts.name + " is a " + facts.kind + ": it has no simulated I/O");
  devices::IoName resolved = io.Resolve(name);
  if (resolved.signal == nullptr) {
    std::string all;
    for (const auto& sig : io.Signals()) {
      if (!inputs_only || sig->direction() == devices::IoDirection::kInput)
        all += (all.empty() ? "" : ", ") + sig->name();
    }
    std::string reason = facts.kind + " has no signal " + Quote(name);
    if (!resolved.error.nearest.empty()) reason += "; nearest: " + JoinNames(resolved.error.nearest);
    s.Fail(name_field, reason + " (its " + (inputs_only ? "inputs" : "signals") + ": " + all + ")");
  }
  if (!resolved.notice.empty()) s.Note(name_field, resolved.notice);
  return resolved;
}

void CheckSdo(const Scope& s, const NodeFacts& facts, std::uint32_t index, std::uint32_t subindex,
              const std::string& type_name, const std::string& value, std::uint32_t port,
              const char* port_field) {
  if (index < 1 || index > 0xFFFF)
    s.Fail("index", std::to_string(index) + " is not an object index (1..0xFFFF)");
  if (subindex > 255) s.Fail("subindex", std::to_string(subindex) + " is not a sub-index (0..255)");
  if (type_name.empty()) s.Fail("type", "required: one of " + std::string(control::SdoTypeNames()));
  const std::optional<control::SdoType> type = control::ParseSdoType(type_name);
  if (!type)
    s.Fail("type", Quote(type_name) + " is not a type (" + std::string(control::SdoTypeNames()) + ")");
  if (value.empty()) s.Fail("value", "required: the value to write");
  try {
    (void)control::EncodeSdoValue(*type, value);
  } catch (const std::exception& e) {
    s.Fail("value", e.what());
  }
  const std::size_t type_size = control::SdoTypeSize(*type);
  if (port >= facts.ports)
    s.Fail(port_field, CanName(port) + " does not exist: " + facts.name + " has " + PortsText(facts.ports));
  const canopen::ObjectDictionary& od = facts.dictionaries->at(port);
  const auto idx = static_cast<std::uint16_t>(index);
  const auto sub = static_cast<std::uint8_t>(subindex);
  const std::string where = Hex(index) + " sub " + std::to_string(subindex);
  if (od.Find(idx) == nullptr) s.Fail("index", facts.kind + " has no object " + Hex(index));
  const canopen::SubObject* object = od.Find(idx, sub);
  if (object == nullptr) s.Fail("subindex", facts.kind + " has no " + where);
  if (object->access == canopen::Access::kRo || object->access == canopen::Access::kConst)
    s.Fail("index", where + " (" + object->name + ") of " + facts.kind + " is read-only");
  const std::optional<std::size_t> size = canopen::FixedSize(object->type);
  if (size && type_size != *size)
    s.Fail("type", type_name + " is " + std::to_string(type_size) + " byte(s) but " + where + " (" +
                       object->name + ") is " + std::to_string(*size));
  if (!size && type_size != 0)
    s.Fail("type", where + " (" + object->name + ") has a variable length: write it as vs, os or d");
}

}  // namespace canfleet::topology::detail
