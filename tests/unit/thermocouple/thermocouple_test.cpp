/// @file Tests of the ITS-90 thermocouple reference functions against the NIST ITS-90 Thermocouple
/// Database (NIST SRD 60; NIST Monograph 175), whose tables IEC 60584-1:2013 reproduces.
///
/// Every reference value below (table points, full-precision points, compensated temperatures)
/// was cross-checked with an independent implementation, the PyPI package thermocouple-its90 1.0.2,
/// which verifies itself against all 12,026 points of the NIST tables.

#include "node/devices/thermocouple/thermocouple.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace canfleet::devices::thermocouple {
namespace {

/// NIST tables print EMF to 1 µV, so a correct reference function is within half of that.
constexpr double kTableToleranceMv = 0.0005;
/// Values computed to full precision (here and by thermocouple-its90) agree to rounding noise.
constexpr double kExactToleranceMv = 1e-9;
/// NIST prints the inverse ranges' EMF bounds to 1 µV, not always rounded to nearest (S: -0.235 and
/// 18.693 mV where the reference function gives -0.23556 and 18.69354 mV).
constexpr double kPrintedBoundToleranceMv = 0.001;
/// The brief's bound on the inverse over every range; the per-type bound below is tighter.
constexpr double kInverseBoundC = 0.1;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Point {
  double celsius;
  double millivolts;
};

struct TypeCase {
  ThermocoupleType type;
  /// NIST SRD 60 table entries (mV at an integer °C): range ends, piece joins and points between.
  std::vector<Point> table;
  /// Off-grid points to full precision (thermocouple-its90), which catch a wrong digit in any
  /// coefficient that the 1 µV table rounding would hide.
  std::vector<Point> exact;
  /// Temperatures where two reference polynomials join (NIST SRD 60 range limits).
  std::vector<double> joins;
  /// Inverse range as NIST prints it in mV (SRD 60 inverse coefficient tables).
  Range printed_inverse_emf;
  /// NIST's widest stated error band of the type's inverse polynomials, plus 0.005 °C because
  /// NIST rounds the bands to 0.01 °C (type K's -200..0 °C piece reaches 0.041 °C against "0.04").
  double inverse_tolerance_c;
};

std::vector<TypeCase> Cases() {
  using T = ThermocoupleType;
  return {
      {T::kB,
       {{0, 0.000},
        {20, -0.003},  // the dip below zero that makes B double-valued up to ~42 °C
        {100, 0.033},
        {250, 0.291},
        {500, 1.242},
        {630, 1.975},
        {631, 1.981},
        {1000, 4.834},
        {1500, 10.099},
        {1820, 13.820}},
       {{312.5, 0.469552036878}, {1234.5, 7.146942211620}},
       {630.615},
       {0.291, 13.820},
       0.035},
      {T::kE,
       {{-270, -9.835},
        {-200, -8.825},
        {-100, -5.237},
        {0, 0.000},
        {100, 6.319},
        {500, 37.005},
        {1000, 76.373}},
       {{-123.4, -6.248383460305}, {456.7, 33.505251876869}},
       {0.0},
       {-8.825, 76.373},
       0.035},
      {T::kJ,
       {{-210, -8.095},
        {-100, -4.633},
        {0, 0.000},
        {100, 5.269},
        {500, 27.393},
        {760, 42.919},
        {1000, 57.953},
        {1200, 69.553}},
       {{-150.5, -6.516318847612}, {888.8, 51.175827048331}},
       {760.0},
       {-8.095, 69.553},
       0.055},
      {T::kK,
       {{-270, -6.458},
        {-200, -5.891},
        {-100, -3.554},
        {0, 0.000},
        {25, 1.000},
        {100, 4.096},
        {300, 12.209},
        {500, 20.644},
        {1000, 41.276},
        {1372, 54.886}},
       {{-250.5, -6.406005962824}, {123.4, 5.059044553448}, {1234.5, 50.088262514410}},
       {0.0},
       {-5.891, 54.886},
       0.065},
      {T::kN,
       {{-270, -4.345},
        {-200, -3.990},
        {-100, -2.407},
        {0, 0.000},
        {100, 2.774},
        {600, 20.613},
        {1000, 36.256},
        {1300, 47.513}},
       {{-222.2, -4.177197583815}, {777.7, 27.578774534812}},
       {0.0},
       {-3.990, 47.513},
       0.045},
      {T::kR,
       {{-50, -0.226},
        {0, 0.000},
        {100, 0.647},
        {250, 1.923},
        {1000, 10.506},
        {1064, 11.361},
        {1065, 11.375},
        {1500, 17.451},
        {1665, 19.746},
        {1768, 21.101}},
       {{-12.3, -0.062911563432}, {1111.1, 12.001148958705}, {1700.0, 20.221696099435}},
       {1064.18, 1664.5},
       {-0.226, 21.103},
       0.025},
      {T::kS,
       {{-50, -0.236},
        {0, 0.000},
        {100, 0.646},
        {250, 1.874},
        {1000, 9.587},
        {1064, 10.332},
        {1065, 10.344},
        {1500, 15.582},
        {1665, 17.542},
        {1768, 18.693}},
       {{12.3, 0.068321263610}, {1333.3, 13.563084427660}, {1750.5, 18.508609311844}},
       {1064.18, 1664.5},
       {-0.235, 18.693},
       0.025},
      {T::kT,
       {{-270, -6.258},
        {-200, -5.603},
        {-100, -3.379},
        {0, 0.000},
        {100, 4.279},
        {200, 9.288},
        {400, 20.872}},
       {{-222.2, -5.916035294507}, {333.3, 16.819638035875}},
       {0.0},
       {-5.603, 20.872},
       0.045},
  };
}

/// gtest prints a failing parameter with this rather than as raw bytes.
void PrintTo(const TypeCase& c, std::ostream* os) {
  *os << "type " << Letter(c.type);
}

class ThermocoupleTypeTest : public ::testing::TestWithParam<TypeCase> {};

// NIST SRD 60 tables: E(t) at printed points within the table's 1 µV rounding.
TEST_P(ThermocoupleTypeTest, ReferenceFunctionMatchesNistTable) {
  const TypeCase& c = GetParam();
  for (const Point& p : c.table) {
    const std::optional<double> emf = EmfFromTemperature(c.type, p.celsius);
    ASSERT_TRUE(emf.has_value()) << p.celsius << " °C";
    EXPECT_NEAR(*emf, p.millivolts, kTableToleranceMv) << p.celsius << " °C";
  }
}

// NIST SRD 60 coefficients to full precision, off the table grid.
TEST_P(ThermocoupleTypeTest, ReferenceFunctionMatchesFullPrecisionPoints) {
  const TypeCase& c = GetParam();
  for (const Point& p : c.exact) {
    const std::optional<double> emf = EmfFromTemperature(c.type, p.celsius);
    ASSERT_TRUE(emf.has_value()) << p.celsius << " °C";
    EXPECT_NEAR(*emf, p.millivolts, kExactToleranceMv) << p.celsius << " °C";
  }
}

// NIST SRD 60 defines the reference function piecewise; the pieces join without a step.
TEST_P(ThermocoupleTypeTest, ReferencePiecesJoinContinuously) {
  const TypeCase& c = GetParam();
  for (double join : c.joins) {
    const std::optional<double> below = EmfFromTemperature(c.type, join);
    const std::optional<double> above = EmfFromTemperature(c.type, std::nextafter(join, kInf));
    ASSERT_TRUE(below && above) << join << " °C";
    EXPECT_NEAR(*below, *above, 1e-6) << join << " °C";
  }
}

// NIST SRD 60 inverse polynomials: T(E(t)) = t within NIST's stated error band, over the whole
// inverse range, every 0.1 °C.
TEST_P(ThermocoupleTypeTest, InverseRoundTripsOverItsRange) {
  const TypeCase& c = GetParam();
  const Range range = InverseTemperatureRange(c.type);
  double worst = 0;
  double worst_at = range.min;
  const int steps = static_cast<int>(std::lround((range.max - range.min) * 10));
  for (int i = 0; i <= steps; ++i) {
    const double celsius = std::min(range.min + i * 0.1, range.max);
    const std::optional<double> emf = EmfFromTemperature(c.type, celsius);
    ASSERT_TRUE(emf.has_value()) << celsius << " °C";
    const std::optional<double> back = TemperatureFromEmf(c.type, *emf);
    ASSERT_TRUE(back.has_value()) << celsius << " °C, " << *emf << " mV";
    if (std::abs(*back - celsius) > worst) {
      worst = std::abs(*back - celsius);
      worst_at = celsius;
    }
  }
  EXPECT_LE(worst, kInverseBoundC) << "at " << worst_at << " °C";
  EXPECT_LE(worst, c.inverse_tolerance_c) << "at " << worst_at << " °C";
}

// The published table EMFs invert to their temperatures (the inverse applied to NIST's numbers,
// not only to our own reference function). A table EMF is off by up to 0.5 µV of rounding, which
// is worth 0.5 µV / Seebeck coefficient in °C: 0.14 °C for R at -50 °C (3.3 µV/°C).
TEST_P(ThermocoupleTypeTest, InverseOfTablePoints) {
  const TypeCase& c = GetParam();
  const Range accepted = InverseEmfRange(c.type);
  const Range range = InverseTemperatureRange(c.type);
  for (const Point& p : c.table) {
    if (p.millivolts < accepted.min || p.millivolts > accepted.max) continue;
    const double lo = std::max(p.celsius - 1, range.min);
    const double hi = std::min(p.celsius + 1, range.max);
    const double seebeck = (*EmfFromTemperature(c.type, hi) - *EmfFromTemperature(c.type, lo)) / (hi - lo);
    const std::optional<double> celsius = TemperatureFromEmf(c.type, p.millivolts);
    ASSERT_TRUE(celsius.has_value()) << p.millivolts << " mV";
    EXPECT_NEAR(*celsius, p.celsius, c.inverse_tolerance_c + kTableToleranceMv / seebeck)
        << p.millivolts << " mV";
  }
}

// Reference function: defined on the closed range, nothing outside it and no NaN.
TEST_P(ThermocoupleTypeTest, ReferenceRangeEdges) {
  const TypeCase& c = GetParam();
  const Range range = TemperatureRange(c.type);
  EXPECT_TRUE(EmfFromTemperature(c.type, range.min).has_value());
  EXPECT_TRUE(EmfFromTemperature(c.type, range.max).has_value());
  EXPECT_FALSE(EmfFromTemperature(c.type, std::nextafter(range.min, -kInf)).has_value());
  EXPECT_FALSE(EmfFromTemperature(c.type, std::nextafter(range.max, kInf)).has_value());
  EXPECT_FALSE(EmfFromTemperature(c.type, range.min - 100).has_value());
  EXPECT_FALSE(EmfFromTemperature(c.type, range.max + 100).has_value());
  EXPECT_FALSE(EmfFromTemperature(c.type, kNaN).has_value());
  EXPECT_FALSE(EmfFromTemperature(c.type, kInf).has_value());
  EXPECT_FALSE(EmfFromTemperature(c.type, -kInf).has_value());
}

// Inverse: accepts NIST's printed EMF range (to its rounding), ends map into the temperature
// range, nothing outside.
TEST_P(ThermocoupleTypeTest, InverseRangeEdges) {
  const TypeCase& c = GetParam();
  const Range emf = InverseEmfRange(c.type);
  const Range celsius = InverseTemperatureRange(c.type);
  EXPECT_NEAR(emf.min, c.printed_inverse_emf.min, kPrintedBoundToleranceMv);
  EXPECT_NEAR(emf.max, c.printed_inverse_emf.max, kPrintedBoundToleranceMv);
  for (double end : {emf.min, emf.max}) {
    const std::optional<double> t = TemperatureFromEmf(c.type, end);
    ASSERT_TRUE(t.has_value()) << end << " mV";
    EXPECT_GE(*t, celsius.min);
    EXPECT_LE(*t, celsius.max);
    // A clamped end still gives an EMF back.
    EXPECT_TRUE(EmfFromTemperature(c.type, *t).has_value());
  }
  EXPECT_NEAR(*TemperatureFromEmf(c.type, emf.min), celsius.min, c.inverse_tolerance_c);
  EXPECT_NEAR(*TemperatureFromEmf(c.type, emf.max), celsius.max, c.inverse_tolerance_c);
  EXPECT_FALSE(TemperatureFromEmf(c.type, std::nextafter(emf.min, -kInf)).has_value());
  EXPECT_FALSE(TemperatureFromEmf(c.type, std::nextafter(emf.max, kInf)).has_value());
  EXPECT_FALSE(TemperatureFromEmf(c.type, emf.max + 1).has_value());
  EXPECT_FALSE(TemperatureFromEmf(c.type, kNaN).has_value());
  EXPECT_FALSE(TemperatureFromEmf(c.type, kInf).has_value());
  EXPECT_FALSE(TemperatureFromEmf(c.type, -kInf).has_value());
}

// Cold-junction compensation: what a meter with its terminals at `cold` reads, compensated back,
// is the hot temperature again (law of intermediate temperatures, IEC 60584-1 reference tables
// assume a 0 °C reference junction).
TEST_P(ThermocoupleTypeTest, ColdJunctionCompensationRoundTrips) {
  const TypeCase& c = GetParam();
  const Range range = InverseTemperatureRange(c.type);
  for (double cold : {0.0, 20.0, 25.0, 50.0}) {
    // Interior points: at the exact ends (E(hot) - E(cold)) + E(cold) may round one ulp outside.
    for (double hot = range.min + 0.5; hot < range.max; hot += 7.5) {
      const std::optional<double> measured = MeasuredEmf(c.type, hot, cold);
      ASSERT_TRUE(measured.has_value()) << hot << " °C hot, " << cold << " °C cold";
      EXPECT_NEAR(*measured, *EmfFromTemperature(c.type, hot) - *EmfFromTemperature(c.type, cold), 1e-12);
      const std::optional<double> back = HotJunctionTemperature(c.type, *measured, cold);
      ASSERT_TRUE(back.has_value()) << hot << " °C hot, " << cold << " °C cold";
      EXPECT_NEAR(*back, hot, c.inverse_tolerance_c) << hot << " °C hot, " << cold << " °C cold";
    }
  }
  // With the cold junction at 0 °C compensation is the plain inverse.
  const double mid_emf = (InverseEmfRange(c.type).min + InverseEmfRange(c.type).max) / 2;
  EXPECT_EQ(HotJunctionTemperature(c.type, mid_emf, 0.0), TemperatureFromEmf(c.type, mid_emf));
}

TEST_P(ThermocoupleTypeTest, ColdJunctionOutOfRange) {
  const TypeCase& c = GetParam();
  const Range range = TemperatureRange(c.type);
  const Range emf = InverseEmfRange(c.type);
  EXPECT_FALSE(MeasuredEmf(c.type, range.max + 1, 25).has_value());
  EXPECT_FALSE(MeasuredEmf(c.type, 500, range.min - 1).has_value());
  EXPECT_FALSE(MeasuredEmf(c.type, kNaN, 25).has_value());
  EXPECT_FALSE(HotJunctionTemperature(c.type, 1.0, range.min - 1).has_value());
  EXPECT_FALSE(HotJunctionTemperature(c.type, 1.0, kNaN).has_value());
  EXPECT_FALSE(HotJunctionTemperature(c.type, kNaN, 25).has_value());
  // The measured EMF alone is in range, but adding E(50 °C) takes it past the inverse range.
  EXPECT_TRUE(TemperatureFromEmf(c.type, emf.max).has_value());
  EXPECT_FALSE(HotJunctionTemperature(c.type, emf.max, 50).has_value());
}

TEST_P(ThermocoupleTypeTest, LetterRoundTrips) {
  const ThermocoupleType type = GetParam().type;
  const char letter = Letter(type);
  EXPECT_EQ(TypeFromLetter(letter), type);
  EXPECT_EQ(TypeFromLetter(static_cast<char>(letter - 'A' + 'a')), type);
}

INSTANTIATE_TEST_SUITE_P(AllTypes, ThermocoupleTypeTest, ::testing::ValuesIn(Cases()),
                         [](const ::testing::TestParamInfo<TypeCase>& param) {
                           return std::string("Type") + Letter(param.param.type);
                         });

// The two values the brief and every K table start from (NIST SRD 60, type K).
TEST(ThermocoupleTest, TypeKReferencePoints) {
  EXPECT_NEAR(*EmfFromTemperature(ThermocoupleType::kK, 100), 4.096, kTableToleranceMv);
  EXPECT_NEAR(*EmfFromTemperature(ThermocoupleType::kK, 1000), 41.276, kTableToleranceMv);
  EXPECT_NEAR(*TemperatureFromEmf(ThermocoupleType::kK, 4.096), 100, 0.05);
  EXPECT_NEAR(*TemperatureFromEmf(ThermocoupleType::kK, 41.276), 1000, 0.05);
}

// Worked compensation examples; the hot temperatures are thermocouple-its90's exact inversions
// (Newton on the reference function), which ours meet within NIST's inverse error band.
TEST(ThermocoupleTest, ColdJunctionCompensationExamples) {
  // A meter reads 4.096 mV with its terminals at 25 °C: not 100 °C but 124.31 °C.
  EXPECT_NEAR(*HotJunctionTemperature(ThermocoupleType::kK, 4.096, 25), 124.309948, 0.06);
  EXPECT_NEAR(*MeasuredEmf(ThermocoupleType::kK, 100, 25), 3.095987864156, kExactToleranceMv);
  EXPECT_NEAR(*HotJunctionTemperature(ThermocoupleType::kJ, 5.0, 30), 123.218747, 0.05);
  EXPECT_NEAR(*HotJunctionTemperature(ThermocoupleType::kT, -2.0, 20), -32.501459, 0.04);
  EXPECT_NEAR(*HotJunctionTemperature(ThermocoupleType::kS, 9.0, 40), 969.346538, 0.02);
  EXPECT_NEAR(*HotJunctionTemperature(ThermocoupleType::kB, 5.0, 30), 1017.809698, 0.02);
}

// NIST gives no type B inverse below 250 °C (0.291 mV): E(t) dips below zero and back up to
// ~42 °C, so an EMF there has two temperatures, and above it rises too slowly (0.3 µV/°C at
// 50 °C) to resolve one. The inverse refuses rather than pick or guess.
TEST(ThermocoupleTest, TypeBRefusesItsDoubleValuedRegion) {
  EXPECT_LT(*EmfFromTemperature(ThermocoupleType::kB, 21), 0);
  EXPECT_GT(*EmfFromTemperature(ThermocoupleType::kB, 50), 0);
  for (double mv : {-0.003, 0.0, 0.1, 0.29}) {
    EXPECT_FALSE(TemperatureFromEmf(ThermocoupleType::kB, mv).has_value()) << mv << " mV";
  }
  EXPECT_TRUE(TemperatureFromEmf(ThermocoupleType::kB, 0.2916).has_value());
}

// The inverse ranges are narrower than the reference ranges (NIST SRD 60: K inverse from -200 °C):
// -250 °C has an EMF, but that EMF has no inverse.
TEST(ThermocoupleTest, InverseNarrowerThanReference) {
  const std::optional<double> emf = EmfFromTemperature(ThermocoupleType::kK, -250);
  ASSERT_TRUE(emf.has_value());
  EXPECT_NEAR(*emf, -6.404, kTableToleranceMv);
  EXPECT_FALSE(TemperatureFromEmf(ThermocoupleType::kK, *emf).has_value());
  EXPECT_FALSE(HotJunctionTemperature(ThermocoupleType::kK, *emf, 0).has_value());
}

// R and S have two inverse polynomials over 1064-1200 °C; the upper one is NIST's tighter fit
// (error bands -0.0005..0.001 °C for R and ±0.0002 °C for S, against ±0.005 and ±0.01 °C).
TEST(ThermocoupleTest, PlatinumTypesUseTheTighterInverseWhereTheyOverlap) {
  for (ThermocoupleType type : {ThermocoupleType::kR, ThermocoupleType::kS}) {
    for (double celsius = 1064.5; celsius <= 1200; celsius += 0.5) {
      const double back = *TemperatureFromEmf(type, *EmfFromTemperature(type, celsius));
      EXPECT_NEAR(back, celsius, 0.001) << Letter(type) << " at " << celsius << " °C";
    }
  }
}

// A value cast into the enum from configuration that names no type gives no result, not UB.
TEST(ThermocoupleTest, UnknownTypeGivesNoResult) {
  const auto unknown = static_cast<ThermocoupleType>(42);
  EXPECT_FALSE(EmfFromTemperature(unknown, 100).has_value());
  EXPECT_FALSE(TemperatureFromEmf(unknown, 1).has_value());
  EXPECT_FALSE(MeasuredEmf(unknown, 100, 25).has_value());
  EXPECT_FALSE(HotJunctionTemperature(unknown, 1, 25).has_value());
  EXPECT_TRUE(std::isnan(TemperatureRange(unknown).min));
  EXPECT_TRUE(std::isnan(InverseEmfRange(unknown).max));
  EXPECT_EQ(Letter(unknown), '?');
  EXPECT_FALSE(TypeFromLetter('X').has_value());
  EXPECT_FALSE(TypeFromLetter('\0').has_value());
}

}  // namespace
}  // namespace canfleet::devices::thermocouple
