#include "orchestrator/topology/expect_checks.hpp"

#include "orchestrator/topology/node_checks.hpp"

#include <cstdlib>
#include <set>

#include "orchestrator/control/sdo_value.hpp"
#include "orchestrator/topology/port_numbering.hpp"

namespace canfleet::topology::detail {

namespace {

/// Hex bytes ("05 80 00", spaces optional): how many, or nullopt when it is not hex bytes.
std::optional<std::size_t> HexByteCount(const std::string& text) {
  std::string digits;
  for (const char c : text) {
    if (c == ' ') continue;
    if (!std::isxdigit(static_cast<unsigned char>(c))) return std::nullopt;
    digits += c;
  }
  if (digits.size() % 2 != 0) return std::nullopt;
  return digits.size() / 2;
}

void CheckHexBytes(const Scope& s, std::string_view field, const std::string& text, std::size_t min,
                   std::size_t max) {
  const auto n = HexByteCount(text);
  if (!n) s.Fail(field, Quote(text) + " is not hex bytes (e.g. \"05 80 00 00 00\")");
  if (*n < min || *n > max)
    s.Fail(field, Quote(text) + " is " + std::to_string(*n) + " byte(s); " +
                      (min == max ? std::to_string(min) : std::to_string(min) + ".." + std::to_string(max)) +
                      " expected");
}

// `port` is 0-based; a port the node lacks is reported at port_field ("can", or the deprecated "port").
const NodeFacts& RequirePort(const Scope& s, const TopologyFacts& facts, const std::string& node,
                             std::uint32_t port, const char* port_field = "port") {
  if (node.empty()) s.Fail("node", "required: the node this expectation is about");
  const NodeFacts& n = facts.RequireNode(s, "node", node);
  if (port >= n.ports)
    s.Fail(port_field, CanName(port) + " does not exist: " + n.name + " has " + PortsText(n.ports));
  return n;
}

std::string RequireBus(const Scope& s, const TopologyFacts& facts, const std::string& bus) {
  if (bus.empty()) {
    if (facts.buses.size() == 1) return facts.buses.begin()->first;
    s.Fail("bus", "required: the topology has several buses (" + facts.BusNames() + ")");
  }
  if (!facts.buses.contains(bus))
    s.Fail("bus", "unknown bus " + Quote(bus) + " (the topology's buses: " + facts.BusNames() + ")");
  return bus;
}

void CheckState(const Scope& s, const std::string& state, const std::set<std::string>& states) {
  std::string known;
  for (const auto& k : states)
    known += (known.empty() ? "" : ", ") + k;
  if (state.empty()) s.Fail("state", "required: one of " + known);
  if (!states.contains(state)) s.Fail("state", Quote(state) + " is not a state (" + known + ")");
}

void CheckSdoExpect(const Scope& s, const TopologyFacts& facts, const SdoExpect& e) {
  const NodeFacts& node = RequirePort(s, facts, e.node(), e.port(), PortFieldName(e));
  if (e.index() < 1 || e.index() > 0xFFFF)
    s.Fail("index", std::to_string(e.index()) + " is not an object index (1..0xFFFF)");
  if (e.subindex() > 255) s.Fail("subindex", std::to_string(e.subindex()) + " is not a sub-index (0..255)");
  const std::optional<control::SdoType> type = control::ParseSdoType(e.type());
  if (e.type().empty() || !type)
    s.Fail("type", (e.type().empty() ? std::string("required") : Quote(e.type()) + " is not a type") + " (" +
                       std::string(control::SdoTypeNames()) + ")");
  if (e.has_abort()) {
    if (!e.value().empty()) s.Fail("abort", "give a value or an abort code, not both");
    if (e.has_mask()) s.Fail("mask", "a mask applies to a value, not to an abort code");
    return;  // an abort may be expected of an object the dictionary lacks
  }
  if (e.value().empty()) s.Fail("value", "required: the value to read (or abort: the abort code)");
  try {
    (void)control::EncodeSdoValue(*type, e.value());
  } catch (const std::exception& ex) {
    s.Fail("value", ex.what());
  }
  const std::string_view name = control::SdoTypeName(*type);
  if (e.has_mask() && (control::SdoTypeSize(*type) == 0 || (name[0] != 'u' && name[0] != 'i')))
    s.Fail("mask", "a mask applies to integer types (u8..u64, i8..i64), not " + e.type());
  const canopen::ObjectDictionary& od = node.dictionaries->at(e.port());
  const std::string where = Hex(e.index()) + " sub " + std::to_string(e.subindex());
  if (od.Find(static_cast<std::uint16_t>(e.index())) == nullptr)
    s.Fail("index",
           node.kind + " has no object " + Hex(e.index()) + " (expect abort: 0x06020000 to test that)");
  const canopen::SubObject* object =
      od.Find(static_cast<std::uint16_t>(e.index()), static_cast<std::uint8_t>(e.subindex()));
  if (object == nullptr) s.Fail("subindex", node.kind + " has no " + where);
  const std::optional<std::size_t> size = canopen::FixedSize(object->type);
  if (size && control::SdoTypeSize(*type) != *size)
    s.Fail("type", e.type() + " is " + std::to_string(control::SdoTypeSize(*type)) + " byte(s) but " + where +
                       " (" + object->name + ") is " + std::to_string(*size));
}

void CheckIoExpect(const Scope& s, const TopologyFacts& facts, const IoExpect& e) {
  const NodeFacts& node = RequirePort(s, facts, e.node(), 0);
  if (e.name().empty()) s.Fail("name", "required: the signal (e.g. OUT1.current_mA)");
  if (node.io == nullptr || node.io->Signals().empty())
    s.Fail("name", "node " + node.name + " is a " + node.kind + ": it has no simulated I/O");
  ResolveSignal(s, "name", node, e.name(), false);
  const bool range = e.has_min() || e.has_max();
  if (!e.value().empty() && range)
    s.Fail(e.has_min() ? "min" : "max", "give a value or a range (min, max), not both");
  if (e.value().empty() && !range) s.Fail("value", "required: the value, or a range (min, max)");
  if (e.has_min() && e.has_max() && e.min() > e.max()) s.Fail("max", "max is below min");
  if (e.tolerance() < 0) s.Fail("tolerance", "must not be negative");
}

void CheckFramesExpect(const Scope& s, const TopologyFacts& facts, const FramesExpect& e,
                       std::uint32_t within) {
  RequireBus(s, facts, e.bus());
  const std::uint32_t max_id = e.extended() ? 0x1FFFFFFF : 0x7FF;
  if (!e.has_cob_id()) s.Fail("cob_id", "required: the identifier (e.g. 0x185)");
  if (e.cob_id() > max_id)
    s.Fail("cob_id", Hex(e.cob_id()) + " is not a " + (e.extended() ? "29" : "11") + "-bit identifier");
  if (e.has_mask() && e.mask() > max_id) s.Fail("mask", Hex(e.mask()) + " is wider than the identifier");
  if (!e.has_at_least() && !e.has_at_most() && e.period_ms() == 0 && e.data().empty())
    s.FailHere("say what to expect of the frames: at_least, at_most (0: not seen), period_ms or data");
  if (e.has_at_least() && e.has_at_most() && e.at_least() > e.at_most())
    s.Fail("at_most", "at_most is below at_least");
  if (e.tolerance_ms() > 0 && e.period_ms() == 0) s.Fail("tolerance_ms", "a tolerance needs period_ms");
  if (e.period_ms() > 0 && within < e.period_ms())
    s.Fail("period_ms", "the window (within_ms " + std::to_string(within) + ") is shorter than one period");
  if (!e.data().empty()) CheckHexBytes(s, "data", e.data(), 1, 8);
  if (!e.data_mask().empty()) {
    if (e.data().empty()) s.Fail("data_mask", "a mask needs data");
    CheckHexBytes(s, "data_mask", e.data_mask(), *HexByteCount(e.data()), *HexByteCount(e.data()));
  }
}

}  // namespace

void CheckExpect(const Scope& s, const TopologyFacts& facts, const Expect& expect) {
  using E = Expect;
  const bool state_kind = expect.has_nmt() || expect.has_sdo() || expect.has_io() || expect.has_controller();
  if (expect.what_case() == E::WHAT_NOT_SET)
    s.FailHere("an expectation needs a kind: emcy, no_emcy, nmt, sdo, io, frames, bus or controller");
  if (expect.within_ms() == 0 && !state_kind)
    s.Fail("within_ms",
           "required: the window's length in ms (only nmt, sdo, io and controller can be judged at one "
           "instant)");
  if (expect.throughout() && !state_kind)
    s.Fail("throughout",
           "applies to nmt, sdo, io and controller (the other kinds say what they judge over the window)");
  switch (expect.what_case()) {
    case E::kEmcy: {
      const Scope es = s.Child("emcy", expect.emcy());
      const EmcyExpect& e = expect.emcy();
      RequirePort(es, facts, e.node(), e.port(), PortFieldName(e));
      if (!e.has_code()) es.Fail("code", "required: the error code (e.g. 0x8130; 0 is the error reset)");
      if (e.code() > 0xFFFF) es.Fail("code", Hex(e.code()) + " is not an EMCY error code (16 bits)");
      if (e.has_error_register() && e.error_register() > 0xFF)
        es.Fail("error_register", Hex(e.error_register()) + " is not an error register (8 bits)");
      if (!e.manufacturer().empty()) CheckHexBytes(es, "manufacturer", e.manufacturer(), 5, 5);
      if (!e.manufacturer_mask().empty()) {
        if (e.manufacturer().empty()) es.Fail("manufacturer_mask", "a mask needs manufacturer bytes");
        CheckHexBytes(es, "manufacturer_mask", e.manufacturer_mask(), 5, 5);
      }
      break;
    }
    case E::kNoEmcy: {
      const Scope es = s.Child("no_emcy", expect.no_emcy());
      const NoEmcyExpect& e = expect.no_emcy();
      if (!e.node().empty()) RequirePort(es, facts, e.node(), e.port(), PortFieldName(e));
      if (e.node().empty() && e.port() != 0) es.Fail(PortFieldName(e), "a port needs a node");
      if (e.has_code() && e.code() > 0xFFFF)
        es.Fail("code", Hex(e.code()) + " is not an EMCY error code (16 bits)");
      break;
    }
    case E::kNmt: {
      const Scope ns = s.Child("nmt", expect.nmt());
      RequirePort(ns, facts, expect.nmt().node(), expect.nmt().port(), PortFieldName(expect.nmt()));
      CheckState(ns, expect.nmt().state(), {"operational", "pre-operational", "stopped"});
      break;
    }
    case E::kSdo:
      CheckSdoExpect(s.Child("sdo", expect.sdo()), facts, expect.sdo());
      break;
    case E::kIo:
      CheckIoExpect(s.Child("io", expect.io()), facts, expect.io());
      break;
    case E::kFrames:
      CheckFramesExpect(s.Child("frames", expect.frames()), facts, expect.frames(), expect.within_ms());
      break;
    case E::kBus: {
      const Scope bs = s.Child("bus", expect.bus());
      const BusExpect& e = expect.bus();
      RequireBus(bs, facts, e.bus());
      const int given =
          (e.has_load_below() ? 1 : 0) + (e.has_load_above() ? 1 : 0) + (e.no_error_frames() ? 1 : 0);
      if (given != 1) bs.FailHere("give exactly one of load_below, load_above, no_error_frames");
      if (e.has_load_below() && (e.load_below() <= 0 || e.load_below() > 100))
        bs.Fail("load_below", "a percentage above 0, at most 100");
      if (e.has_load_above() && (e.load_above() < 0 || e.load_above() >= 100))
        bs.Fail("load_above", "a percentage from 0, below 100");
      break;
    }
    case E::kController: {
      const Scope cs = s.Child("controller", expect.controller());
      RequirePort(cs, facts, expect.controller().node(), expect.controller().port(),
                  PortFieldName(expect.controller()));
      CheckState(cs, expect.controller().state(), {"bus-off", "error-active", "error-passive"});
      break;
    }
    case E::WHAT_NOT_SET:
      break;
  }
}

}  // namespace canfleet::topology::detail
