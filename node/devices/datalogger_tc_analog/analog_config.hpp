#pragma once
/// @file The configuration rules of the data logger's ten inputs (UMAX181001 §1.3, §1.4, Tables 5-7,
/// 10-12, §3.4.1-3.4.6): what an SDO write may set (validators) and what writing a "key object"
/// reloads when 5550h "Enable Automatic Updates" is TRUE (Table 11).
///
/// Validators (SDO writes; the device's own writes are not checked):
/// - 6112h: 0, 1, 20 on every input; 10 (digital) on inputs 8-10 only (Table 5).         06090030h
/// - 6110h sub 1-10: 40, 50 everywhere; 60 and 10000 on inputs 8 and 9 only (Table 6).  06090030h
/// - 2100h: voltage 0 (0-5 V) or 1 (0-10 V, inputs 1-7 only); current 0 or 1; frequency and PWM 0
///   (Table 7).                                                                            06090031h
/// - 2102h: writable only while 5550h is FALSE (§3.4.6).                                  08000022h
/// - 2010h/2020h sub 1-7: "will not be allowed to change" (§3.4.1-3.4.2): only 0.          06090030h
/// - Table 12 (damaged; the text's rules): 0 <= 7148h <= 7120h <= 7122h <= MAX,
///   7122h <= 7149h <= 110 % of MAX, 0 <= 2111h <= 10 % of MAX, 4-20 mA: 7120h >= 4 mA,
///   frequency: 7120h >= 0.5 Hz. MAX is the range's full scale in field-value units (5 V, 10 V,
///   20 mA, 50 kHz, 3000.0 rpm, 100.0 %, 1 for digital, times 10^2102h).             06090031h/32h
///
/// Automatic updates (5550h TRUE; §1.4 Tables 10-11, §1.8): when the input's class (sensor type x
/// range, RPM when 2101h != 0, digital when 6112h = 10) changes through 6110h, 2100h, 2101h or
/// 6112h, the device writes 2102h, 7148h, 7120h, 7122h, 7149h and 2111h from Table 11; a new 6110h
/// first puts 2100h back to its default range 0 (Table 7 "the default value for each range ...
/// 2100h will automatically be updated"), and types other than frequency/PWM set 2020h = 0 (§1.4).

#include <optional>

#include "node/canopen/od/object_dictionary.hpp"
#include "node/devices/blocks/analog_input_defaults.hpp"

namespace canfleet::devices::datalogger {

/// The Table 11 row input `ch` (0-based) is configured for; nullopt for a combination Table 6/7
/// does not have (possible only with 5550h FALSE or an edited EDS).
std::optional<blocks::InputRange> ClassifyChannel(const canopen::ObjectDictionary& od, int ch);

/// MAX of Table 12 in the range's base unit (V, mA, Hz, rpm, %, on/off).
double FullScale(blocks::InputRange range);

/// Writes the Table 11 row of `range` into input `ch`'s dependent objects (device writes).
void ApplyInputDefaults(canopen::ObjectDictionary& od, int ch, blocks::InputRange range);

/// Installs the validators above on `od` (the shared application objects).
void InstallAnalogValidators(canopen::ObjectDictionary& od);

}  // namespace canfleet::devices::datalogger
