#pragma once
/// @file Thermocouple reference functions of ITS-90 for the letter-designated types B, E, J, K, N,
/// R, S and T, in both directions, and cold-junction compensation.
///
/// Source: NIST ITS-90 Thermocouple Database (NIST SRD 60; NIST Monograph 175, Burns et al. 1993),
/// whose reference functions IEC 60584-1:2013 adopts. A simulated temperature transmitter needs
/// the EMF a real thermocouple would produce (to fill a field value in mV) and the temperature a
/// real transmitter would compute from it, so both directions follow the published functions
/// rather than a fit of our own:
/// - EMF from temperature: the reference polynomial of the range the temperature lies in (type K
///   adds its exponential term above 0 °C). Defined over each type's full table range.
/// - Temperature from EMF: NIST's inverse polynomials, which cover a narrower range than the
///   reference functions (e.g. type K from -200 °C; type B from 250 °C, its EMF being
///   double-valued up to ~42 °C and nearly flat above) and agree with the reference functions
///   within NIST's stated error bands (at most 0.06 °C). No iteration: a transmitter's
///   linearisation does the same.
///
/// All EMFs are in mV against a reference junction at 0 °C; temperatures in °C (ITS-90).
/// Out-of-range or NaN inputs give std::nullopt; nothing here extrapolates a polynomial.

#include <optional>

namespace canfleet::devices::thermocouple {

/// The letter-designated types of IEC 60584-1.
enum class ThermocoupleType { kB, kE, kJ, kK, kN, kR, kS, kT };

/// A closed interval [min, max].
struct Range {
  double min = 0;
  double max = 0;
};

/// The type's letter ('K' for kK), for messages and test names.
char Letter(ThermocoupleType type);

/// The type for a letter (either case), or nullopt for a letter that names no type.
std::optional<ThermocoupleType> TypeFromLetter(char letter);

/// °C over which the reference function (EmfFromTemperature) is defined, e.g. [-270, 1372] for K.
Range TemperatureRange(ThermocoupleType type);

/// °C over which the inverse polynomials (TemperatureFromEmf) are defined, e.g. [-200, 1372] for K.
Range InverseTemperatureRange(ThermocoupleType type);

/// mV accepted by TemperatureFromEmf: the reference function at the ends of InverseTemperatureRange.
Range InverseEmfRange(ThermocoupleType type);

/// Thermoelectric EMF in mV of a thermocouple whose measuring junction is at `celsius` and whose
/// reference junction is at 0 °C; nullopt outside TemperatureRange.
std::optional<double> EmfFromTemperature(ThermocoupleType type, double celsius);

/// Measuring-junction temperature in °C for an EMF in mV with the reference junction at 0 °C;
/// nullopt outside InverseEmfRange.
std::optional<double> TemperatureFromEmf(ThermocoupleType type, double millivolts);

/// The EMF in mV a meter reads when the reference (cold) junction sits at `cold_celsius` rather
/// than 0 °C: E(hot) - E(cold), since EMFs of junctions in series add (the law of intermediate
/// temperatures). nullopt when either temperature is outside TemperatureRange.
std::optional<double> MeasuredEmf(ThermocoupleType type, double hot_celsius, double cold_celsius);

/// Cold-junction compensation: the measuring-junction temperature in °C for a `measured_millivolts`
/// read with the reference junction at `cold_celsius`, i.e. T(measured + E(cold)). nullopt when
/// the cold junction is outside TemperatureRange or the compensated EMF outside InverseEmfRange.
std::optional<double> HotJunctionTemperature(ThermocoupleType type, double measured_millivolts,
                                             double cold_celsius);

}  // namespace canfleet::devices::thermocouple
