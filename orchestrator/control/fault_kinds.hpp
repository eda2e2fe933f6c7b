#pragma once
/// @file What each fault kind takes from a FaultSpec: one row per kind, read by everything that
/// deals with faults. The topology loader checks scenario steps with it, the fleet's FaultManager
/// checks what the control API asks for, the CLI names the kinds and writes its help from it.
/// Adding a fault kind is one row here (and its name in canfleet_control.proto) plus its behaviour
/// in FaultManager.
///
/// An option a kind does not take is refused, never ignored: `bus-off --cob-id 0x185` is an
/// error that says what bus-off takes.

#include <array>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

#include "orchestrator/control/canfleet_control.pb.h"

namespace canfleet::control {

/// The options of a FaultSpec (its fields but kind and label: every kind takes a label).
enum class FaultOption : std::uint8_t {
  kNode,
  kBus,
  kReceivers,
  kCobId,
  kMask,
  kExtended,
  kProbability,
  kSeed,
  kDelay,
  kJitter,
  kDuration,
  kCount,
  kGroups,
  kManualRecovery,
};
inline constexpr std::size_t kFaultOptionCount = 14;

/// A set of FaultOptions.
class FaultOptions {
 public:
  constexpr FaultOptions() = default;
  constexpr FaultOptions(std::initializer_list<FaultOption> options) {
    for (const FaultOption o : options)
      bits_ |= Bit(o);
  }
  constexpr bool Has(FaultOption o) const { return (bits_ & Bit(o)) != 0; }
  constexpr bool Empty() const { return bits_ == 0; }
  friend constexpr FaultOptions operator|(FaultOptions a, FaultOptions b) {
    FaultOptions both;
    both.bits_ = a.bits_ | b.bits_;
    return both;
  }

 private:
  static constexpr std::uint32_t Bit(FaultOption o) { return std::uint32_t{1} << static_cast<unsigned>(o); }
  std::uint32_t bits_ = 0;
};

/// Where a fault acts, which decides what must exist for it: a port on a bus, or a process the
/// orchestrator supervises (not an external node).
enum class FaultTarget : std::uint8_t {
  kBus,      ///< broker rules or the node's controller (design decision 3)
  kProcess,  ///< the node's process (Supervisor)
};

/// A requirement of a kind: at least one of `any_of` is given. `text` completes "<KIND> ..." and
/// names options in braces by their FaultSpec field ("{cob_id}"), spelled per FaultSpelling.
struct FaultRequirement {
  FaultOptions any_of;
  std::string_view text;
};

struct FaultKindTraits {
  FaultKind kind = FAULT_KIND_UNSPECIFIED;
  std::string_view name;                    ///< the CLI's name: "heartbeat-loss"
  std::string_view help;                    ///< what it does, one line, for `fault inject --help`
  FaultOptions takes;                       ///< the options it reads; any other is refused
  std::array<FaultRequirement, 2> needs{};  ///< what it cannot do without
  /// Options that are alternative forms: at most one of them (bus-off until cleared, or held).
  FaultOptions one_of{};
  FaultTarget target = FaultTarget::kBus;
  /// An event, not a state: done at once, nothing to clear (restart, power-cycle).
  bool one_shot = false;
};

/// Every kind, in the enum's order.
const std::array<FaultKindTraits, 13>& FaultKinds();
/// The row of `kind`, or nullptr for FAULT_KIND_UNSPECIFIED and unknown values.
const FaultKindTraits* TraitsOf(FaultKind kind);

/// How messages name kinds and options: as the topology file writes them ("BUS_OFF", "cob_id")
/// or as the CLI takes them ("bus-off", "--cob-id"). The control API speaks the CLI's language:
/// its errors are printed by `canfleet`.
enum class FaultSpelling : std::uint8_t { kTopology, kCli };

/// `option` spelled for `spelling`: "cob_id" / "--cob-id".
std::string_view OptionName(FaultOption option, FaultSpelling spelling);

/// What is wrong with a FaultSpec.
struct FaultSpecProblem {
  std::string field;  ///< its FaultSpec field: "cob_id", "groups", "kind"
  int index = -1;     ///< the element of a repeated field, or -1
  std::string reason;
};

/// Checks a spec against its kind's row, from the spec alone (nodes and buses are for the caller,
/// which knows the fleet): a kind is given; every option given is taken by the kind; what it
/// requires is there; alternative forms are not mixed; identifiers fit 11 (29) bits and the mask
/// too; the probability is within 0..1; a partition has at least 2 groups. The caller fills in
/// defaults it has first (the bus of the node, the only bus of the fleet). nullopt when sound.
///   BUS_OFF with cob_id, topology: {"cob_id", -1, "cob_id does not apply to BUS_OFF (it takes node,
///   bus, duration_ms, manual_recovery, label)"}
///   the same from the CLI: "--cob-id does not apply to bus-off (it takes --node, --bus,
///   --duration, --manual-recovery, --label)"
std::optional<FaultSpecProblem> CheckFaultSpec(const FaultSpec& spec, FaultSpelling spelling);

/// Whether the fault is an event rather than a state: a one-shot kind, or a bus-off that recovers
/// as usual (neither manual recovery nor held for a duration).
bool IsOneShot(const FaultSpec& spec);

}  // namespace canfleet::control
