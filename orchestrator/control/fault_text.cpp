#include "orchestrator/control/fault_text.hpp"

#include <cctype>
#include <sstream>

#include "orchestrator/control/duration_text.hpp"

namespace canfleet::control {

namespace {

std::string Join(const google::protobuf::RepeatedPtrField<std::string>& names) {
  std::string out;
  for (const auto& n : names)
    out += (out.empty() ? "" : ", ") + n;
  return out;
}

std::string Hex(std::uint32_t value, int digits) {
  std::ostringstream s;
  s << "0x" << std::uppercase << std::hex;
  s.width(digits);
  s.fill('0');
  s << value;
  return s.str();
}

/// "frames 0x185", "frames 0x180/0x780", "all frames", "all extended frames".
std::string Frames(const FaultSpec& spec) {
  if (!spec.has_cob_id()) return spec.extended() ? "all extended frames" : "all frames";
  const int digits = spec.extended() ? 8 : 3;
  const std::uint32_t exact = spec.extended() ? 0x1FFFFFFFu : 0x7FFu;
  std::string text = "frames " + Hex(spec.cob_id(), digits);
  if (spec.has_mask() && spec.mask() != exact) text += "/" + Hex(spec.mask(), digits);
  return text;
}

std::string OnBus(const FaultSpec& spec) {
  return spec.bus().empty() ? "" : " on " + spec.bus();
}

std::string Receivers(const FaultSpec& spec) {
  return spec.receivers().empty() ? " (to all receivers)" : " (to " + Join(spec.receivers()) + ")";
}

std::string Probability(const FaultSpec& spec) {
  if (spec.probability() <= 0.0 || spec.probability() >= 1.0) return "";
  std::ostringstream s;
  s << ", probability " << spec.probability();
  if (spec.seed() != 0) s << " (seed " << spec.seed() << ")";
  return s.str();
}

/// ", for 5s", ", for 10 frames", ", for 5s or 10 frames", ", until cleared".
std::string Lifetime(const FaultSpec& spec) {
  std::string text;
  if (spec.duration_ms() != 0) text = FormatDuration(std::chrono::milliseconds(spec.duration_ms()));
  if (spec.count() != 0) {
    if (!text.empty()) text += " or ";
    text += std::to_string(spec.count()) + (spec.count() == 1 ? " frame" : " frames");
  }
  return text.empty() ? ", until cleared" : ", for " + text;
}

std::string Groups(const FaultSpec& spec) {
  std::string out;
  for (int i = 0; i < spec.groups_size(); ++i) {
    if (i != 0) out += i + 1 == spec.groups_size() ? " and " : ", ";
    out += "[" + Join(spec.groups(i).nodes()) + "]";
  }
  return out.empty() ? "no groups" : out;
}

std::string Normalised(std::string_view name) {
  std::string out;
  for (const char c : name)
    out += c == '_' ? '-' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

std::string_view FaultKindName(FaultKind kind) {
  const FaultKindTraits* traits = TraitsOf(kind);
  return traits != nullptr ? traits->name : "unspecified";
}

std::optional<FaultKind> ParseFaultKind(std::string_view name) {
  const std::string n = Normalised(name);
  for (const FaultKindTraits& k : FaultKinds())
    if (k.name == n) return k.kind;
  return std::nullopt;
}

const std::vector<std::string>& FaultKindNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const FaultKindTraits& k : FaultKinds())
      v.emplace_back(k.name);
    return v;
  }();
  return names;
}

std::string FormatCanId(std::uint32_t id, bool extended) {
  return Hex(id, extended ? 8 : 3);
}

std::string SummarizeFault(const FaultSpec& spec) {
  const std::string kind(FaultKindName(spec.kind()));
  const std::string node = spec.node().empty() ? "?" : spec.node();
  switch (spec.kind()) {
    case BUS_OFF:
      if (spec.duration_ms() != 0)
        return kind + " of " + node + OnBus(spec) + ", held for " +
               FormatDuration(std::chrono::milliseconds(spec.duration_ms())) +
               " (every recovery attempt fails until then)";
      return kind + " of " + node + OnBus(spec) +
             (spec.manual_recovery() ? ", manual recovery (until cleared)"
                                     : ", recovering after 128 x 11 recessive bits");
    case HEARTBEAT_LOSS:
      return kind + " of " + node + OnBus(spec) + Receivers(spec) + Probability(spec) + Lifetime(spec);
    case RPDO_TIMEOUT:
      return kind + " of " + node + OnBus(spec) + " (" +
             (spec.has_cob_id() ? Frames(spec) : std::string("no cob_id given:")) + " no longer reach it)" +
             Lifetime(spec);
    case DROP:
    case DELAY:
    case CORRUPT:
    case DUPLICATE: {
      std::string text = kind + " of " + Frames(spec) + " from " +
                         (spec.node().empty() ? "any node" : spec.node()) + OnBus(spec);
      if (spec.kind() == DELAY) {
        text += " by " + FormatDuration(std::chrono::milliseconds(spec.delay_ms()));
        if (spec.jitter_ms() != 0)
          text += " + 0.." + FormatDuration(std::chrono::milliseconds(spec.jitter_ms()));
      }
      // Corruption and duplication act on the wire: every receiver sees them.
      if (spec.kind() == DROP || spec.kind() == DELAY) text += Receivers(spec);
      return text + Probability(spec) + Lifetime(spec);
    }
    case PARTITION:
      return kind + " of " + (spec.bus().empty() ? node + "'s bus" : spec.bus()) + " into " + Groups(spec) +
             Lifetime(spec);
    case BABBLING_IDIOT:
      return kind + " " + node + OnBus(spec) + " (floods " +
             FormatCanId(spec.has_cob_id() ? spec.cob_id() : 0x001, spec.extended()) +
             " at the bus's full rate)" + Lifetime(spec);
    case ERROR_PASSIVE:
    case KILL:
      return kind + " of " + node + (spec.kind() == ERROR_PASSIVE ? OnBus(spec) : "") + Lifetime(spec);
    case RESTART:
    case POWER_CYCLE:
      return kind + " of " + node;
    default:
      return "unspecified fault";
  }
}

}  // namespace canfleet::control
