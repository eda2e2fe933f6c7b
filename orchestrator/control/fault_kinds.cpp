#include "orchestrator/control/fault_kinds.hpp"

#include <sstream>

namespace canfleet::control {

namespace {

using O = FaultOption;

/// Options of the frame faults (drop, delay, corrupt, duplicate): which frames, how often, how long.
constexpr FaultOptions kFrameOptions{O::kNode,        O::kBus,  O::kCobId,    O::kMask, O::kExtended,
                                     O::kProbability, O::kSeed, O::kDuration, O::kCount};

// The one table. `takes` lists every option a kind reads (label: all of them); `needs` what it
// cannot do without. Texts name options by field in braces; see FaultRequirement.
const std::array<FaultKindTraits, 13> kKinds{{
    {.kind = BUS_OFF,
     .name = "bus-off",
     .help = "--node's controller goes bus-off and recovers as usual; until cleared with --manual-recovery; "
             "held for --duration (every recovery attempt fails until then)",
     .takes = {O::kNode, O::kBus, O::kDuration, O::kManualRecovery},
     .needs = {{{{O::kNode}, "needs the node whose controller goes bus-off ({node})"}}},
     .one_of = {O::kDuration, O::kManualRecovery}},
    {.kind = HEARTBEAT_LOSS,
     .name = "heartbeat-loss",
     .help = "--node's heartbeat is not delivered (to --receiver nodes, or all)",
     .takes = {O::kNode, O::kBus, O::kReceivers, O::kProbability, O::kSeed, O::kDuration, O::kCount},
     .needs = {{{{O::kNode}, "needs the node whose heartbeat is lost ({node})"}}}},
    {.kind = RPDO_TIMEOUT,
     .name = "rpdo-timeout",
     .help = "frames --cob-id no longer reach --node",
     .takes = {O::kNode, O::kBus, O::kCobId, O::kExtended, O::kDuration},
     .needs = {{{{O::kNode}, "needs the node that stops receiving the RPDO ({node})"},
                {{O::kCobId}, "needs the COB-ID of the RPDO that stops reaching the node ({cob_id})"}}}},
    {.kind = DROP,
     .name = "drop",
     .help = "frames from --node (or any node) matching --cob-id/--mask are dropped (for --receiver nodes, "
             "or all)",
     .takes = kFrameOptions | FaultOptions{O::kReceivers}},
    {.kind = DELAY,
     .name = "delay",
     .help = "... delayed by --delay plus 0..--jitter",
     .takes = kFrameOptions | FaultOptions{O::kReceivers, O::kDelay, O::kJitter},
     .needs = {{{{O::kDelay, O::kJitter}, "needs {delay_ms} or {jitter_ms}"}}}},
    {.kind = CORRUPT,
     .name = "corrupt",
     .help = "... destroyed by an error frame (TEC/REC consequences; on the wire: every receiver)",
     .takes = kFrameOptions},
    {.kind = DUPLICATE,
     .name = "duplicate",
     .help = "... received twice (on the wire: every receiver)",
     .takes = kFrameOptions},
    {.kind = PARTITION,
     .name = "partition",
     .help = "--group sets of nodes on --bus (or --node's bus) no longer hear each other",
     .takes = {O::kNode, O::kBus, O::kGroups, O::kDuration},
     .needs = {{{{O::kBus}, "without {node} needs {bus}, the bus to split"}}}},
    {.kind = BABBLING_IDIOT,
     .name = "babbling-idiot",
     .help = "--node floods --cob-id (default 0x001) at the bus's full rate",
     .takes = {O::kNode, O::kBus, O::kCobId, O::kExtended, O::kDuration},
     .needs = {{{{O::kNode}, "needs the node that floods the bus ({node})"}}}},
    {.kind = ERROR_PASSIVE,
     .name = "error-passive",
     .help = "--node's controller is held error-passive",
     .takes = {O::kNode, O::kBus, O::kDuration},
     .needs = {{{{O::kNode}, "needs the node whose controller is held error-passive ({node})"}}}},
    {.kind = KILL,
     .name = "kill",
     .help = "--node's process is killed until the fault is cleared",
     .takes = {O::kNode, O::kDuration},
     .needs = {{{{O::kNode}, "needs the node whose process is killed ({node})"}}},
     .target = FaultTarget::kProcess},
    {.kind = RESTART,
     .name = "restart",
     .help = "--node's process is stopped and started again",
     .takes = {O::kNode},
     .needs = {{{{O::kNode}, "needs the node whose process restarts ({node})"}}},
     .target = FaultTarget::kProcess,
     .one_shot = true},
    {.kind = POWER_CYCLE,
     .name = "power-cycle",
     .help = "--node's process is killed and started again",
     .takes = {O::kNode},
     .needs = {{{{O::kNode}, "needs the node whose power is cycled ({node})"}}},
     .target = FaultTarget::kProcess,
     .one_shot = true},
}};

struct OptionNames {
  std::string_view field;  ///< FaultSpec field, as the topology writes it
  std::string_view cli;
};

// Indexed by FaultOption.
constexpr std::array<OptionNames, kFaultOptionCount> kOptionNames{{
    {"node", "--node"},
    {"bus", "--bus"},
    {"receivers", "--receiver"},
    {"cob_id", "--cob-id"},
    {"mask", "--mask"},
    {"extended", "--extended"},
    {"probability", "--probability"},
    {"seed", "--seed"},
    {"delay_ms", "--delay"},
    {"jitter_ms", "--jitter"},
    {"duration_ms", "--duration"},
    {"count", "--count"},
    {"groups", "--group"},
    {"manual_recovery", "--manual-recovery"},
}};

/// Whether `spec` gives `option` (proto3: a default value is "not given"; probability 0 means 1).
bool Given(const FaultSpec& spec, FaultOption option) {
  switch (option) {
    case O::kNode:
      return !spec.node().empty();
    case O::kBus:
      return !spec.bus().empty();
    case O::kReceivers:
      return spec.receivers_size() > 0;
    case O::kCobId:
      return spec.has_cob_id();
    case O::kMask:
      return spec.has_mask();
    case O::kExtended:
      return spec.extended();
    case O::kProbability:
      return spec.probability() != 0.0;
    case O::kSeed:
      return spec.seed() != 0;
    case O::kDelay:
      return spec.delay_ms() != 0;
    case O::kJitter:
      return spec.jitter_ms() != 0;
    case O::kDuration:
      return spec.duration_ms() != 0;
    case O::kCount:
      return spec.count() != 0;
    case O::kGroups:
      return spec.groups_size() > 0;
    case O::kManualRecovery:
      return spec.manual_recovery();
  }
  return false;
}

std::string_view KindText(const FaultKindTraits& kind, FaultSpelling spelling) {
  return spelling == FaultSpelling::kCli ? kind.name : FaultKind_Name(kind.kind);
}

/// `text` with every "{field}" replaced by that option's name in `spelling`.
std::string Spell(std::string_view text, FaultSpelling spelling) {
  std::string out;
  while (!text.empty()) {
    const auto open = text.find('{');
    const auto close = text.find('}', open);
    if (open == std::string_view::npos || close == std::string_view::npos) break;
    out += text.substr(0, open);
    const std::string_view field = text.substr(open + 1, close - open - 1);
    bool known = false;
    for (std::size_t o = 0; o < kFaultOptionCount; ++o) {
      if (kOptionNames[o].field != field) continue;
      out += OptionName(static_cast<FaultOption>(o), spelling);
      known = true;
    }
    if (!known) out += field;
    text.remove_prefix(close + 1);
  }
  return out + std::string(text);
}

/// "node, bus, duration_ms, manual_recovery, label".
std::string Takes(const FaultKindTraits& kind, FaultSpelling spelling) {
  std::string out;
  for (std::size_t o = 0; o < kFaultOptionCount; ++o)
    if (kind.takes.Has(static_cast<FaultOption>(o)))
      out += std::string(OptionName(static_cast<FaultOption>(o), spelling)) + ", ";
  return out + (spelling == FaultSpelling::kCli ? "--label" : "label");
}

std::string Hex(std::uint32_t value) {
  std::ostringstream out;
  out << "0x" << std::hex << std::uppercase << value;
  return out.str();
}

std::string KindList() {
  std::string out;
  for (const FaultKindTraits& k : kKinds)
    out += (out.empty() ? "" : ", ") + FaultKind_Name(k.kind);
  return out;
}

}  // namespace

const std::array<FaultKindTraits, 13>& FaultKinds() {
  return kKinds;
}

const FaultKindTraits* TraitsOf(FaultKind kind) {
  for (const FaultKindTraits& k : kKinds)
    if (k.kind == kind) return &k;
  return nullptr;
}

std::string_view OptionName(FaultOption option, FaultSpelling spelling) {
  const OptionNames& names = kOptionNames[static_cast<std::size_t>(option)];
  return spelling == FaultSpelling::kCli ? names.cli : names.field;
}

std::optional<FaultSpecProblem> CheckFaultSpec(const FaultSpec& spec, FaultSpelling spelling) {
  const FaultKindTraits* kind = TraitsOf(spec.kind());
  if (kind == nullptr)
    return FaultSpecProblem{"kind", -1,
                            spelling == FaultSpelling::kCli ? "say which fault (kind)"
                                                            : "required: a fault kind (" + KindList() + ")"};
  const std::string kind_text(KindText(*kind, spelling));
  auto field = [](FaultOption o) { return std::string(OptionName(o, FaultSpelling::kTopology)); };

  for (std::size_t o = 0; o < kFaultOptionCount; ++o) {
    const auto option = static_cast<FaultOption>(o);
    if (kind->takes.Has(option) || !Given(spec, option)) continue;
    return FaultSpecProblem{field(option), -1,
                            std::string(OptionName(option, spelling)) + " does not apply to " + kind_text +
                                " (it takes " + Takes(*kind, spelling) + ")"};
  }
  for (const FaultRequirement& r : kind->needs) {
    if (r.any_of.Empty()) continue;
    bool met = false;
    std::optional<FaultOption> first;
    for (std::size_t o = 0; o < kFaultOptionCount; ++o) {
      const auto option = static_cast<FaultOption>(o);
      if (!r.any_of.Has(option)) continue;
      if (!first) first = option;
      met = met || Given(spec, option);
    }
    if (!met)
      return FaultSpecProblem{field(*first), -1, "required: " + kind_text + " " + Spell(r.text, spelling)};
  }
  std::optional<FaultOption> form;
  for (std::size_t o = 0; o < kFaultOptionCount; ++o) {
    const auto option = static_cast<FaultOption>(o);
    if (!kind->one_of.Has(option) || !Given(spec, option)) continue;
    if (form)
      return FaultSpecProblem{field(option), -1,
                              std::string(OptionName(*form, spelling)) + " and " +
                                  std::string(OptionName(option, spelling)) + " are two forms of " +
                                  kind_text + ": give one"};
    form = option;
  }

  const std::uint32_t id_limit = spec.extended() ? 0x1FFFFFFF : 0x7FF;
  const std::string width = spec.extended() ? "29" : "11";
  if (spec.has_cob_id() && spec.cob_id() > id_limit)
    return FaultSpecProblem{"cob_id", -1,
                            Hex(spec.cob_id()) + " does not fit a " + width + "-bit identifier"};
  if (spec.has_mask() && spec.mask() > id_limit)
    return FaultSpecProblem{"mask", -1, Hex(spec.mask()) + " does not fit a " + width + "-bit identifier"};
  if (spec.has_mask() && !spec.has_cob_id())
    return FaultSpecProblem{"mask", -1,
                            std::string(OptionName(O::kMask, spelling)) + " needs " +
                                std::string(OptionName(O::kCobId, spelling)) + ", the identifier it masks"};
  if (!(spec.probability() >= 0.0 && spec.probability() <= 1.0))
    return FaultSpecProblem{"probability", -1, std::to_string(spec.probability()) + " is outside 0..1"};
  if (kind->takes.Has(O::kGroups) && spec.groups_size() < 2)
    return FaultSpecProblem{"groups", 0,
                            kind_text + " needs at least 2 groups of nodes" +
                                (spelling == FaultSpelling::kCli ? " (--group a,b --group c)" : "") + "; " +
                                std::to_string(spec.groups_size()) + " given"};
  return std::nullopt;
}

bool IsOneShot(const FaultSpec& spec) {
  const FaultKindTraits* kind = TraitsOf(spec.kind());
  if (kind == nullptr) return false;
  if (spec.kind() == BUS_OFF) return !spec.manual_recovery() && spec.duration_ms() == 0;
  return kind->one_shot;
}

}  // namespace canfleet::control
