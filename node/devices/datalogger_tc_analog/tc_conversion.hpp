#pragma once
/// @file What one thermocouple channel of the data logger measures (UMAX181001 §1.2, §3.3.2-3.3.4,
/// §3.4.19-3.4.21): the hot and cold junction temperatures of the simulated world become the EMF
/// at the terminals, which the node converts back the way the manual describes.
///
/// §1.2 names no linearisation; the reference functions of IEC 60584-1 / NIST ITS-90 are the
/// standard a TC module implements (library node/devices/thermocouple/). Per conversion:
///   measured EMF  V   = E(T_hot) - E(T_cj)            (what the ADC reads, "raw microvolt", 6130h)
///   cold junction V_cj = E(T_cj)                      (2162h, "the cold junction value in mV")
///   reading       T   = E^-1(V + V_cj)  with 2160h TRUE (compensated, 6100h)
///                 T   = E^-1(V)         with 2160h FALSE (relative to the terminals)
/// Temperatures outside a type's table range are held at its ends (a real junction cannot produce
/// an EMF the table does not have). EMFs outside NIST's inverse polynomials (type B below 250 C,
/// types K/T/E/J/N below their inverse range) are solved from the reference function by bisection;
/// type B below ~40 C is ambiguous (|EMF| < 3 uV) and reads the root the search finds.

#include <cstdint>
#include <optional>

#include "node/devices/thermocouple/thermocouple.hpp"

namespace canfleet::devices::datalogger {

/// 6110h sub 11-14 (Table 1: the value column is lost to OCR; list order with K = 2, README C26):
/// 1 J, 2 K, 3 N, 4 R, 5 S, 6 T, 7 B, 8 E. nullopt for other values.
std::optional<thermocouple::ThermocoupleType> TcTypeFromCode(std::uint16_t code);

struct TcReading {
  double measured_mv = 0;       ///< EMF at the terminals
  double cold_junction_mv = 0;  ///< E(T_cj) of the channel's type
  double temperature_c = 0;     ///< the converted reading (compensated or not)
};

/// One conversion (see the file comment).
TcReading ConvertThermocouple(thermocouple::ThermocoupleType type, double hot_c, double cold_c,
                              bool compensate);

/// E^-1 over the type's whole table range: NIST's inverse polynomial where it is defined, else a
/// bisection of the reference function; held at the range ends beyond them.
double TemperatureFromEmfWide(thermocouple::ThermocoupleType type, double millivolts);

/// E(T) with T held to the type's table range.
double EmfClamped(thermocouple::ThermocoupleType type, double celsius);

}  // namespace canfleet::devices::datalogger
