#pragma once
/// @file (source, number) wiring of the Axiomatic function blocks, with each product's numbering
/// as data.
///
/// Every block input of the family is a pair: a source type (which kind of block) and a number
/// (which instance, usually the sub-index of its output object). The three manuals number the
/// source types differently:
///
/// | code | valve UMAX020411A Table 15/16 | encoder AX023241 Table 6/7 | logger UMAX181001 Table 13/14 |
/// |---|---|---|---|
/// | 0 | not used | not used | not used |
/// | 1 | CANopen message 1-24 | received CAN message 1-5 | CANopen message 1-12 |
/// | 2 | analog input 1-12 | quadrature encoder input 1-2 | analog input 1-10 |
/// | 3 | constant 1-15 | output target value 1-2 | thermocouple cold junction 1-4 |
/// | 4 | PID 1-4 | output current feedback 1-2 | thermocouple degrees 1-4 |
/// | 5 | lookup table 1-12 | lookup table 1-3 | constant 1-15 |
/// | 6 | math 1-6 | math 1-2 | lookup table 1-12 |
/// | 7 | logic 1-4 | programmable logic 1 | math 1-6 |
/// | 8 | output commanded FV 1-12 | PID 1 | logic 1-4 |
/// | 9 | output feedback 1-12 | control constant 1-10 | power supply (number N/A) |
/// | 10 | power supply (number N/A) | set/reset block 1-2 | processor temperature (N/A) |
/// | 11 | processor temperature (N/A) | diagnostic trouble code 1-3 | - |
/// | 12 | - | power supply 1 | - |
/// | 13 | - | processor temperature 1 | - |
///
/// The logger's value column is damaged by OCR; its codes follow the list order (digest §3.4).
/// Blocks never look at codes: they ask for a SourceKind, and the product's resolver maps
/// (kind, number) to its objects. Validation treats the number of "not used" and of the "N/A"
/// sources as ignored (any value): the objects' defaults pair source 0 with number x (valve
/// §3.4.53 2454h default x), so rejecting such pairs would reject the device's own defaults.
///
/// Tick order and loop rule: see signal.hpp (inputs -> math -> LUT -> logic -> PID -> outputs; a
/// block reading itself or a later block sees the previous tick).

#include <cstdint>
#include <functional>
#include <optional>
#include <span>

#include "node/devices/blocks/signal.hpp"

namespace canfleet::devices::blocks {

/// What a source code means, independent of the product's numbering.
enum class SourceKind : std::uint8_t {
  kNotUsed,
  kCanMessage,
  kAnalogInput,  ///< valve/logger AI (7100h or 6020h), encoder QD/frequency/PWM input
  kConstant,
  kPid,
  kLookupTable,
  kMath,
  kLogic,
  kOutputCommand,   ///< valve 7330h / encoder "output target value"
  kOutputFeedback,  ///< valve 2370h / encoder "output current feedback"
  kSupplyVoltage,
  kProcessorTemperature,
  kColdJunction,  ///< logger 2162h
  kThermocouple,  ///< logger 6100h
  kSetReset,      ///< encoder only; no objects in its manual
  kDiagnosticCode,
};

/// One row of a product's source table.
struct SourceType {
  std::uint8_t code = 0;
  SourceKind kind = SourceKind::kNotUsed;
  std::uint8_t first_number = 0;
  std::uint8_t last_number = 0;
  /// Table 16 "N/A" (and "not used"): the number is not looked at.
  bool number_ignored = false;
  /// Valve Table 16 note: "for diagnostic feedback, should not be selected as a control source
  /// for logic inputs". Information only: the manual does not say such writes are refused.
  bool diagnostic_only = false;
};

/// A block input as stored in its two objects (e.g. 2453h/2454h, 3yz0h/3yz1h).
struct SourceRef {
  std::uint8_t source = 0;
  std::uint8_t number = 0;
  friend bool operator==(const SourceRef&, const SourceRef&) = default;
};

/// Reads the current output of block `number` of kind `kind` (the product's objects).
using SignalResolver = std::function<Signal(SourceKind kind, std::uint8_t number)>;

/// A product's wiring: its source table plus its resolver.
class ControlSources {
 public:
  ControlSources(std::span<const SourceType> types, SignalResolver resolver);

  /// The row of `code`, or nullptr if the product has no such source.
  const SourceType* Find(std::uint8_t code) const;
  /// The kind of `code`; unknown codes read as kNotUsed.
  SourceKind KindOf(std::uint8_t code) const;
  /// The code of `kind` in this product, if it has one.
  std::optional<std::uint8_t> CodeOf(SourceKind kind) const;

  /// Whether `code` exists (SDO validator of a source object).
  bool IsSourceAllowed(std::uint8_t code) const { return Find(code) != nullptr; }
  /// Whether the pair may be configured (SDO validator of a source or number object, called with
  /// the pair as it would be after the write). Returns false for an unknown source or a number
  /// outside the source's range.
  bool IsAllowed(SourceRef ref) const;

  /// The signal of `ref`: NotAvailable() for "not used" and for a pair that is not allowed.
  Signal Resolve(SourceRef ref) const;
  /// The signal of block `number` of `kind` (a logic block reading its lookup tables).
  Signal Resolve(SourceKind kind, std::uint8_t number) const;

  std::span<const SourceType> types() const { return types_; }

 private:
  std::span<const SourceType> types_;
  SignalResolver resolver_;
};

/// Valve 12in/12out, UMAX020411A §1.5 Tables 15 and 16.
std::span<const SourceType> ValveSourceTypes();
/// Encoder dual valve, AX023241 §1.3 Tables 6 and 7.
std::span<const SourceType> EncoderSourceTypes();
/// Data logger TC/analog, UMAX181001 §1.4 Tables 13 and 14.
std::span<const SourceType> DataLoggerSourceTypes();

}  // namespace canfleet::devices::blocks
