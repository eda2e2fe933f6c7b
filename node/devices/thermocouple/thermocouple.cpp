/// @file Evaluation of the ITS-90 thermocouple polynomials; the coefficients are in
/// thermocouple_coefficients.cpp.

#include "node/devices/thermocouple/thermocouple.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

#include "node/devices/thermocouple/thermocouple_coefficients.hpp"

namespace canfleet::devices::thermocouple {
namespace {

using detail::Piece;
using detail::TypeCoefficients;

/// A range no value is inside (every comparison with NaN is false), for a type outside the enum.
constexpr Range kNoRange{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};

/// False for NaN too, which is why callers test "inside" rather than "outside".
bool Inside(double value, Range range) {
  return value >= range.min && value <= range.max;
}

/// sum c[i] * x^i by Horner's rule: fewer roundings than summing powers, which matters for the
/// 14th-degree type T polynomial whose terms nearly cancel.
double Polynomial(std::span<const double> c, double x) {
  double sum = 0;
  for (auto it = c.rbegin(); it != c.rend(); ++it)
    sum = sum * x + *it;
  return sum;
}

Range Span(std::span<const Piece> pieces) {
  return {pieces.front().min_celsius, pieces.back().max_celsius};
}

/// The reference function at a temperature already known to be inside its range. At a bound shared
/// by two pieces the lower piece is used; NIST's pieces join there to well below 1 µV.
double Reference(const TypeCoefficients& c, double celsius) {
  const Piece* piece = &c.reference.back();
  for (const Piece& candidate : c.reference) {
    if (celsius <= candidate.max_celsius) {
      piece = &candidate;
      break;
    }
  }
  double emf = Polynomial(piece->coefficients, celsius);
  if (piece->exponential != nullptr) {
    const detail::Exponential& e = *piece->exponential;
    const double offset = celsius - e.a2;
    emf += e.a0 * std::exp(e.a1 * offset * offset);
  }
  return emf;
}

Range InverseEmf(const TypeCoefficients& c) {
  const Range celsius = Span(c.inverse);
  return {Reference(c, celsius.min), Reference(c, celsius.max)};
}

}  // namespace

char Letter(ThermocoupleType type) {
  switch (type) {
    case ThermocoupleType::kB:
      return 'B';
    case ThermocoupleType::kE:
      return 'E';
    case ThermocoupleType::kJ:
      return 'J';
    case ThermocoupleType::kK:
      return 'K';
    case ThermocoupleType::kN:
      return 'N';
    case ThermocoupleType::kR:
      return 'R';
    case ThermocoupleType::kS:
      return 'S';
    case ThermocoupleType::kT:
      return 'T';
  }
  return '?';
}

std::optional<ThermocoupleType> TypeFromLetter(char letter) {
  for (ThermocoupleType type :
       {ThermocoupleType::kB, ThermocoupleType::kE, ThermocoupleType::kJ, ThermocoupleType::kK,
        ThermocoupleType::kN, ThermocoupleType::kR, ThermocoupleType::kS, ThermocoupleType::kT}) {
    const char upper = Letter(type);
    if (letter == upper || letter == upper - 'A' + 'a') return type;
  }
  return std::nullopt;
}

Range TemperatureRange(ThermocoupleType type) {
  const TypeCoefficients* c = detail::Coefficients(type);
  return c != nullptr ? Span(c->reference) : kNoRange;
}

Range InverseTemperatureRange(ThermocoupleType type) {
  const TypeCoefficients* c = detail::Coefficients(type);
  return c != nullptr ? Span(c->inverse) : kNoRange;
}

Range InverseEmfRange(ThermocoupleType type) {
  const TypeCoefficients* c = detail::Coefficients(type);
  return c != nullptr ? InverseEmf(*c) : kNoRange;
}

std::optional<double> EmfFromTemperature(ThermocoupleType type, double celsius) {
  const TypeCoefficients* c = detail::Coefficients(type);
  if (c == nullptr || !Inside(celsius, Span(c->reference))) return std::nullopt;
  return Reference(*c, celsius);
}

std::optional<double> TemperatureFromEmf(ThermocoupleType type, double millivolts) {
  const TypeCoefficients* c = detail::Coefficients(type);
  if (c == nullptr || !Inside(millivolts, InverseEmf(*c))) return std::nullopt;
  // The highest piece that starts at or below the EMF: where R's and S's pieces overlap
  // (1064-1200 °C) the upper one is NIST's tighter fit (error bands -0.0005..0.001 °C for R and
  // ±0.0002 °C for S, against ±0.005 and ±0.01 °C for the 250-1200 °C pieces).
  const Piece* piece = &c->inverse.front();
  for (const Piece& candidate : c->inverse) {
    if (millivolts >= Reference(*c, candidate.min_celsius)) piece = &candidate;
  }
  // The inverse polynomials miss the reference function by up to 0.06 °C; clamping keeps a result
  // at an end of the range inside it, so it can be fed back to EmfFromTemperature.
  const Range celsius = Span(c->inverse);
  return std::clamp(Polynomial(piece->coefficients, millivolts), celsius.min, celsius.max);
}

std::optional<double> MeasuredEmf(ThermocoupleType type, double hot_celsius, double cold_celsius) {
  const std::optional<double> hot = EmfFromTemperature(type, hot_celsius);
  const std::optional<double> cold = EmfFromTemperature(type, cold_celsius);
  if (!hot || !cold) return std::nullopt;
  return *hot - *cold;
}

std::optional<double> HotJunctionTemperature(ThermocoupleType type, double measured_millivolts,
                                             double cold_celsius) {
  const std::optional<double> cold = EmfFromTemperature(type, cold_celsius);
  if (!cold) return std::nullopt;
  return TemperatureFromEmf(type, measured_millivolts + *cold);
}

}  // namespace canfleet::devices::thermocouple
