#pragma once
/// @file Simulated I/O (design decision 5): every device variant declares named inputs that a test
/// (or the control API) sets and named outputs it reads, with units in the name ("IN1.voltage_mV",
/// "IN6.frequency_Hz", "OUT1.current_mA", "OUT2.load" = open|short|nominal). The naming and unit
/// rules and every product's signals: node/devices/README.md "Signals"; Add enforces the unit rule
/// (a number's unit is one of kSignalUnits and ends its name) and the telemetry's 30 characters.
///
/// Values are typed: a number (with a unit and an inclusive range), a bool, or one of an enum's
/// names. Setting an input checks the name, the direction, the type and the range and says what is
/// wrong in one line; nothing is changed then. Every declared input starts at a default inside
/// its normal range, so an idle node raises no faults. Listeners hear every change of any signal
/// (an input set to a new value, an output the device moved), for telemetry.
///
/// Old names (aliases, one table per product in its `<variant>_io.cpp`) keep working: a set or read
/// through one converts the unit if it changed and returns a deprecation notice naming the new
/// name. A device may say which inputs its present configuration does not read (SetIgnoredHook):
/// setting one is accepted, and the status carries a notice saying so, never silently.
///
/// Threading: like the rest of a node, used from the node's event-loop thread only.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace canfleet::devices {

/// The units a number signal may have, each with how it ends the signal's name (node/devices/README.md
/// "Signals", the unit rule): mV, mA, ohm, Hz, pct, C, rpm, counts ...
struct SignalUnit {
  std::string_view unit;    ///< as shown beside a value: "mV", "counts/s"
  std::string_view suffix;  ///< how the name ends after '_' or '.': "mV", "counts_s"
};
std::span<const SignalUnit> SignalUnits();

/// Telemetry carries a signal's name as an IDL string<31> (telemetry/canfleet_telemetry.idl).
inline constexpr std::size_t kMaxSignalNameLength = 30;

enum class IoDirection : std::uint8_t {
  kInput,   ///< set by a test or the control API, read by the device
  kOutput,  ///< set by the device, read by a test or telemetry
};

enum class IoKind : std::uint8_t { kNumber, kBool, kEnum };

/// A signal value: a number, a bool, or the name of one of an enum's choices.
using IoValue = std::variant<double, bool, std::string>;

/// How a signal is declared.
struct IoSpec {
  std::string name;  ///< "<CHANNEL>.<quantity>[_<unit>]", e.g. "IN1.voltage_mV"
  IoKind kind = IoKind::kNumber;
  std::string unit;                  ///< numbers only, e.g. "mV"; empty for bool and enum
  double min = 0;                    ///< numbers: inclusive range an input accepts
  double max = 0;                    ///< (outputs are not range-checked)
  std::vector<std::string> choices;  ///< enums: the accepted names
  IoValue initial;                   ///< the power-on value; inputs: inside the normal range
  std::string description;           ///< one line for listings
};

/// Declaration helpers: NumberSpec("IN1.voltage_mV", "mV", 0, 36000, 2500, "voltage at the pin").
IoSpec NumberSpec(std::string name, std::string unit, double min, double max, double initial,
                  std::string description);
IoSpec BoolSpec(std::string name, bool initial, std::string description);
IoSpec EnumSpec(std::string name, std::vector<std::string> choices, std::string initial,
                std::string description);

/// One declared signal. The device keeps a reference (signals never move) and reads it on its
/// tick; outputs are written through SimulatedIo::Publish so that listeners hear the change.
class IoSignal {
 public:
  const IoSpec& spec() const { return spec_; }
  const std::string& name() const { return spec_.name; }
  IoDirection direction() const { return direction_; }
  IoKind kind() const { return spec_.kind; }

  const IoValue& value() const { return value_; }
  /// The value as a number (bool: 0/1, enum: the index of the choice).
  double Number() const;
  bool Bool() const;
  /// The enum choice ("" for other kinds).
  std::string_view Enum() const;
  /// True when this enum signal currently holds `choice`.
  bool Is(std::string_view choice) const { return Enum() == choice; }
  /// "2500 mV", "true", "open".
  std::string ToString() const;

 private:
  friend class SimulatedIo;
  IoSignal(IoSpec spec, IoDirection direction);
  IoSpec spec_;
  IoDirection direction_;
  IoValue value_;
};

/// The result of setting an input: empty error = done. A notice is a done set's word of warning
/// (an old name, a quantity the pin's configuration does not read), for the user to see.
struct [[nodiscard]] IoStatus {
  IoStatus() = default;
  IoStatus(std::string why) : error(std::move(why)) {}  // NOLINT: `return {"why"};` is a refusal
  std::string error;
  std::string notice;
  std::vector<std::string> nearest;  ///< unknown name: the nearest declared names (NearestNames)
  bool unknown = false;              ///< the error is "no such signal"
  bool ok() const { return error.empty(); }
};

/// An old signal name (node/devices/README.md "Signals", the alias tables): its value is the new
/// signal's times `factor` (AIN1.current_uA = IN1.current_mA x 1000).
struct IoAlias {
  std::string old_name;
  std::string new_name;
  double factor = 1.0;
};

/// A name as the caller wrote it, resolved: the signal, and for an old name the alias and its notice.
struct IoName {
  const IoSignal* signal = nullptr;  ///< null: unknown (see error)
  const IoAlias* alias = nullptr;    ///< set when `name` is an old name
  std::string notice;                ///< "IN1.voltage_mV is deprecated: use IN1.voltage_mV"
  IoStatus error;                    ///< unknown: the message and the nearest names
  /// The value as the caller's name reads it: the new signal's, converted back for an old name
  /// whose unit changed; `unit` likewise.
  std::string ValueText() const;
  std::string Unit() const;
};

/// The ignored hook's one line: "IN2.level is set, but IN2's configuration (6112h sub 2 = 1, 6110h
/// sub 2 = 40) does not read it (it reads IN2.voltage_mV)"; `hint` (in the parentheses) may be empty.
std::string IgnoredNotice(const IoSignal& set, std::string_view configuration, std::string_view hint);

/// The named signals of one device.
class SimulatedIo {
 public:
  using Listener = std::function<void(const IoSignal&)>;

  SimulatedIo() = default;
  SimulatedIo(const SimulatedIo&) = delete;
  SimulatedIo& operator=(const SimulatedIo&) = delete;

  // ---- Device side --------------------------------------------------------------------------
  /// Declares an input. Names are unique; a duplicate or malformed declaration is a programming
  /// error and throws std::logic_error (devices declare their signals once, at construction).
  IoSignal& AddInput(IoSpec spec);
  /// Declares an output.
  IoSignal& AddOutput(IoSpec spec);
  /// Sets an output (the device's view of its pins). Listeners run if the value changed.
  void Publish(IoSignal& output, IoValue value);
  /// Declares an old name of a declared signal. A programming error (unknown new name, a name taken,
  /// a factor on a non-number) throws std::logic_error.
  void AddAlias(IoAlias alias);
  /// The product's alias table, added (AddAlias) the first time a name is not a current one: an
  /// idle node that is only ever asked current names never holds the table (bench/idle).
  void SetAliasTable(std::vector<IoAlias> (*table)()) { alias_table_ = table; }
  /// The device's word on inputs its present configuration does not read: the hook returns why
  /// (one line naming the objects that decide), or "" when `input` is read. Called after each set.
  void SetIgnoredHook(std::function<std::string(const IoSignal& input)> hook) {
    ignored_hook_ = std::move(hook);
  }
  /// Puts every input back to its declared initial value (a device reset does not do this: the
  /// world outside the device does not reset with it; tests may).
  void ResetInputs();

  // ---- Test / control side ------------------------------------------------------------------
  /// Sets an input; checks name, direction, kind and range (numbers) or choice (enums).
  IoStatus Set(std::string_view name, const IoValue& value);
  IoStatus SetNumber(std::string_view name, double value) { return Set(name, IoValue{value}); }
  IoStatus SetBool(std::string_view name, bool value) { return Set(name, IoValue{value}); }
  IoStatus SetEnum(std::string_view name, std::string_view choice) {
    return Set(name, IoValue{std::string(choice)});
  }
  /// Parses `text` for the signal's kind ("2500", "true"/"false"/"on"/"off"/"1"/"0", "open") and
  /// sets it: the entry point for command lines and the control API.
  IoStatus SetText(std::string_view name, std::string_view text);

  /// The signal of that (current) name, or null. Old names: Resolve.
  const IoSignal* Find(std::string_view name) const;
  /// A current or an old name; an unknown one gets the nearest names in `error`.
  IoName Resolve(std::string_view name) const;
  /// Every alias, in declaration order.
  const std::vector<std::unique_ptr<IoAlias>>& Aliases() const;
  /// Typed reads for tests. Throw std::out_of_range for an unknown name (a typo in a test should
  /// fail loudly).
  double Number(std::string_view name) const;
  bool Bool(std::string_view name) const;
  std::string Enum(std::string_view name) const;

  /// Every signal in declaration order.
  const std::vector<std::unique_ptr<IoSignal>>& Signals() const { return signals_; }

  /// Registers a change listener; returns a handle for Unsubscribe.
  std::size_t Subscribe(Listener listener);
  void Unsubscribe(std::size_t handle);

 private:
  IoSignal& Add(IoSpec spec, IoDirection direction);
  const IoSignal& Get(std::string_view name) const;
  void Store(IoSignal& signal, IoValue value);
  IoStatus Unknown(std::string_view name) const;
  /// Appends the ignored hook's notice for `signal` to `status`.
  void NoticeIgnored(const IoSignal& signal, IoStatus& status) const;

  std::vector<std::unique_ptr<IoSignal>> signals_;
  /// Adds the alias table if it was not yet (const: it changes no signal, only what names resolve).
  void LoadAliases() const;

  mutable std::vector<std::unique_ptr<IoAlias>> aliases_;
  mutable std::map<std::string, const IoAlias*, std::less<>> alias_by_name_;
  mutable std::vector<IoAlias> (*alias_table_)() = nullptr;
  std::function<std::string(const IoSignal&)> ignored_hook_;
  std::map<std::string, IoSignal*, std::less<>> by_name_;
  std::map<std::size_t, Listener> listeners_;
  std::size_t next_handle_ = 1;
};

}  // namespace canfleet::devices
