#include "node/devices/blocks/control_source.hpp"

#include <array>
#include <utility>

namespace canfleet::devices::blocks {
namespace {

using K = SourceKind;

constexpr SourceType Numbered(std::uint8_t code, SourceKind kind, std::uint8_t first, std::uint8_t last,
                              bool diagnostic_only = false) {
  return SourceType{code, kind, first, last, false, diagnostic_only};
}

constexpr SourceType Unnumbered(std::uint8_t code, SourceKind kind, bool diagnostic_only = false) {
  return SourceType{code, kind, 0, 0, true, diagnostic_only};
}

// UMAX020411A Table 15 (codes) and Table 16 (numbers). RPDO 1-8 = 7300h/6200h.1, 9-12 = 6200h.2,
// 13-24 = 2500h.1-12. Sources 8-11 are "diagnostic feedback" (note under Table 16).
constexpr std::array kValve{
    Unnumbered(0, K::kNotUsed),
    Numbered(1, K::kCanMessage, 1, 24),
    Numbered(2, K::kAnalogInput, 1, 12),
    Numbered(3, K::kConstant, 1, 15),
    Numbered(4, K::kPid, 1, 4),
    Numbered(5, K::kLookupTable, 1, 12),
    Numbered(6, K::kMath, 1, 6),
    Numbered(7, K::kLogic, 1, 4),
    Numbered(8, K::kOutputCommand, 1, 12, true),
    Numbered(9, K::kOutputFeedback, 1, 12, true),
    Unnumbered(10, K::kSupplyVoltage, true),
    Unnumbered(11, K::kProcessorTemperature, true),
};

// AX023241 Table 6 (codes) and Table 7 (number ranges; "Control Not Used [0]" is still ignored,
// see the header).
constexpr std::array kEncoder{
    Unnumbered(0, K::kNotUsed),
    Numbered(1, K::kCanMessage, 1, 5),
    Numbered(2, K::kAnalogInput, 1, 2),
    Numbered(3, K::kOutputCommand, 1, 2),
    Numbered(4, K::kOutputFeedback, 1, 2),
    Numbered(5, K::kLookupTable, 1, 3),
    Numbered(6, K::kMath, 1, 2),
    Numbered(7, K::kLogic, 1, 1),
    Numbered(8, K::kPid, 1, 1),
    Numbered(9, K::kConstant, 1, 10),
    Numbered(10, K::kSetReset, 1, 2),
    Numbered(11, K::kDiagnosticCode, 1, 3),
    Numbered(12, K::kSupplyVoltage, 1, 1),
    Numbered(13, K::kProcessorTemperature, 1, 1),
};

// UMAX181001 Table 13 (value column damaged: list order) and Table 14. Supply and temperature
// are "for diagnostic feedback" (Table 14 note, as in the valve).
constexpr std::array kDataLogger{
    Unnumbered(0, K::kNotUsed),
    Numbered(1, K::kCanMessage, 1, 12),
    Numbered(2, K::kAnalogInput, 1, 10),
    Numbered(3, K::kColdJunction, 1, 4),
    Numbered(4, K::kThermocouple, 1, 4),
    Numbered(5, K::kConstant, 1, 15),
    Numbered(6, K::kLookupTable, 1, 12),
    Numbered(7, K::kMath, 1, 6),
    Numbered(8, K::kLogic, 1, 4),
    Unnumbered(9, K::kSupplyVoltage, true),
    Unnumbered(10, K::kProcessorTemperature, true),
};

}  // namespace

ControlSources::ControlSources(std::span<const SourceType> types, SignalResolver resolver)
    : types_(types), resolver_(std::move(resolver)) {}

const SourceType* ControlSources::Find(std::uint8_t code) const {
  for (const SourceType& t : types_) {
    if (t.code == code) return &t;
  }
  return nullptr;
}

SourceKind ControlSources::KindOf(std::uint8_t code) const {
  const SourceType* t = Find(code);
  return t == nullptr ? SourceKind::kNotUsed : t->kind;
}

std::optional<std::uint8_t> ControlSources::CodeOf(SourceKind kind) const {
  for (const SourceType& t : types_) {
    if (t.kind == kind) return t.code;
  }
  return std::nullopt;
}

bool ControlSources::IsAllowed(SourceRef ref) const {
  const SourceType* t = Find(ref.source);
  if (t == nullptr) return false;
  if (t->number_ignored) return true;
  return ref.number >= t->first_number && ref.number <= t->last_number;
}

Signal ControlSources::Resolve(SourceRef ref) const {
  const SourceType* t = Find(ref.source);
  if (t == nullptr || t->kind == SourceKind::kNotUsed || !IsAllowed(ref)) return Signal::NotAvailable();
  return Resolve(t->kind, ref.number);
}

Signal ControlSources::Resolve(SourceKind kind, std::uint8_t number) const {
  if (kind == SourceKind::kNotUsed || !resolver_) return Signal::NotAvailable();
  return resolver_(kind, number);
}

std::span<const SourceType> ValveSourceTypes() {
  return kValve;
}
std::span<const SourceType> EncoderSourceTypes() {
  return kEncoder;
}
std::span<const SourceType> DataLoggerSourceTypes() {
  return kDataLogger;
}

}  // namespace canfleet::devices::blocks
