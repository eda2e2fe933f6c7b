#pragma once
/// @file The published polynomial coefficients behind thermocouple.hpp (internal to the library).
///
/// Kept apart from the evaluation code so the tables can be read against the NIST ITS-90
/// Thermocouple Database (NIST SRD 60 / Monograph 175, reproduced in IEC 60584-1) line by line.

#include <span>

#include "node/devices/thermocouple/thermocouple.hpp"

namespace canfleet::devices::thermocouple::detail {

/// Type K's extra term above 0 °C: a0 * exp(a1 * (t - a2)^2) (NIST SRD 60, type K reference function).
struct Exponential {
  double a0;
  double a1;
  double a2;
};

/// One piece of a piecewise polynomial: sum of coefficients[i] * x^i, valid for a temperature in
/// [min_celsius, max_celsius]. For an inverse polynomial x is the EMF in mV and the bounds are
/// still in °C: the EMF bounds follow from the reference function, so that the reference function
/// and its inverse accept exactly matching ranges (NIST prints the EMF bounds rounded to 1 µV).
struct Piece {
  double min_celsius;
  double max_celsius;
  std::span<const double> coefficients;
  /// Added to a reference function's polynomial where NIST gives one (type K above 0 °C only).
  const Exponential* exponential = nullptr;
};

/// Pieces in ascending temperature; adjacent pieces of a reference function share their bound.
/// Inverse pieces may overlap (R and S: 250-1200 °C and 1064-1664.5 °C).
struct TypeCoefficients {
  std::span<const Piece> reference;
  std::span<const Piece> inverse;
};

/// The tables of `type`; nullptr for a value outside the enumeration (e.g. a cast from a
/// configuration number), which the public functions turn into "no result" rather than UB.
const TypeCoefficients* Coefficients(ThermocoupleType type);

}  // namespace canfleet::devices::thermocouple::detail
