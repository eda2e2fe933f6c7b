#pragma once
/// @file What the valve accepts over SDO and what it updates by itself (UMAX020411A §1.3 Tables
/// 4-6, 9-11; §1.5 Tables 14-17; §1.7.1, §1.7.4; §3.3-3.4 value ranges; §3.4.108 5550h).
///
/// Refused writes (values the EDS limits already refuse are not repeated here):
/// | object | rule | abort |
/// |---|---|---|
/// | 6110h | the pin's sensor types (input_ranges.hpp) | 06090030h |
/// | 6112h | Table 4; DI2/DI4 only 0 or 10 | 06090030h |
/// | 2100h | Table 6 for the current 6110h | 06090030h |
/// | 2102h | only while 5550h is FALSE ("normally read-only") | 08000022h |
/// | 7148h, 7120h, 7122h, 7149h, 2111h | Table 11 for the current type/range (input_ranges.hpp) | 06090032h /
/// 06090031h | | 6310h | OUT1-8: 0, 10, 20, 40, 1000, 1020; DO1-4: 0, 1000 (Table 14, §1.4) | 06090030h | |
/// 7320h / 7322h | 7320h < 7322h ("must always be smaller") | 06090031h / 06090032h | | 7321h, 7323h, 7341h,
/// 2300h | 0 .. the type's maximum (current 2.5 A, voltage 24 V, PWM 100 %, digital 1) | 06090032h /
/// 06090031h | | 2311h | up to 10 % of the larger of 7321h, 7323h | 06090031h | | 2220h / 2221h | hold <=
/// hotshot <= 2.5 A | 06090032h / 06090031h | | 2520h / 2522h | 2520h < 2522h | 06090031h / 06090032h | |
/// 5022h / 5023h | under <= over | 06090031h / 06090032h | | number objects (2341h, 2351h, 2361h, 2454h,
/// 2456h, 3yz1h, 4y01h, condition subs 2 and 4) | Table 16 range of the source currently set | 06090032h /
/// 06090031h | | 3yz6h | data response: X1 <= X2 <= ... <= X11 within INTEGER16 (§1.7.1, §3.4.68); time
/// response: X1 = 0, X2..X11 1..86 400 000 ms (§1.7.4) | 06090032h / 06090031h | A source object accepts
/// every Table 15 code (its EDS limits); a pair that does not fit (e.g. the number of a CANopen message left
/// behind an analog input source) reads as "not used" until the number is written, so the two objects can be
/// written in either order.
///
/// Automatic updates (5550h TRUE, SDO writes only; the device's own and stored values never
/// cascade):
/// - 6110h: 2100h := 0 (Table 6 default), 2020h := 0 for voltage, current and resistive (§1.3), then
///   the Table 10 row; 2100h, 6112h, and 2101h between zero and non-zero (Hz <-> RPM): the Table 10
///   row. A row sets 2102h, 7148h, 7120h, 7122h, 7149h, 2111h and, so that PV = FV again (§1.3),
///   7121h := 7120h, 7123h := 7122h, 6132h := 2102h. Values beyond INTEGER16 are held at its limit
///   (RPM span end 33000 -> 32767).
/// - 6310h (§1.5 "all objects related to the output ... are automatically updated"): 7320h/7321h
///   and 7322h/7323h := the type's Table 14 range (current 300/1500 mA, voltage 5000/24000 mV, PWM
///   100/900 = 10.0/90.0 %, digital and hotshot 0/1), 6302h := 3 (current, voltage), 1 (PWM), 0
///   (digital); 6332h := 1 for PWM, else 0; 7341h/2300h := 500/750 mA for current (the factory
///   values), else held into the new 7321h..7323h range.
/// - 3yz5h sub 1 to time response: 3yz3h := 0 and point 1 := (0 ms, 0) (§1.7.4).

#include <array>
#include <optional>

#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/blocks/analog_input_defaults.hpp"
#include "node/devices/valve_12in12out/valve_objects.hpp"

namespace canfleet::devices::valve {

class ValveRules {
 public:
  /// Installs the validators and the auto-update listeners on `stack`'s dictionary.
  explicit ValveRules(canopen::CanopenStack& stack);
  ValveRules(const ValveRules&) = delete;
  ValveRules& operator=(const ValveRules&) = delete;

  /// Re-reads what each input is configured as (after reset application restored parameters).
  void Resync();

 private:
  void InstallInputRules(int ch);
  void InstallOutputRules(int ch);
  void InstallSourceRules();
  void InstallLookupTableRules(int table);
  void InstallMiscRules();
  /// Loads the Table 10 row of input `ch` if its class is not the one loaded last.
  void LoadInputDefaults(int ch, bool force);
  void LoadOutputDefaults(int ch);
  bool AutoUpdate() const;
  std::optional<blocks::InputRange> ClassOf(int ch) const;

  canopen::ObjectDictionary& od_;
  /// What the last cascade (or Resync) saw: the class of each input, 6110h and 6310h.
  std::array<std::optional<blocks::InputRange>, kInputs> loaded_{};
  std::array<std::int64_t, kInputs> sensor_type_{};
  std::array<std::int64_t, kOutputs> output_type_{};
};

}  // namespace canfleet::devices::valve
