// Thermocouple inputs of the data logger (UMAX181001 §1.2, §3.3.2-3.3.4, §3.4.19-3.4.26, §4,
// Table 26): conversion per type against NIST ITS-90 table points, cold-junction compensation,
// the 400 ms conversion, open circuit and the four limit flags with hysteresis.

#include <cmath>

#include "node/devices/datalogger_tc_analog/datalogger_objects.hpp"
#include "node/devices/datalogger_tc_analog/tc_conversion.hpp"
#include "node/devices/thermocouple/thermocouple.hpp"
#include "tests/unit/datalogger/datalogger_fixture.hpp"

namespace canfleet::devices::test {
namespace {

using namespace datalogger;

struct TypePoint {
  std::uint16_t code;  // 6110h sub 11-14 (Table 1, list order)
  char letter;
  double celsius;
  double millivolts;  // NIST ITS-90 table (Monograph 175), reference junction 0 C
};

// One published point per type, each inside the INTEGER16 uV range of 6130h.
constexpr TypePoint kPoints[] = {
    {1, 'J', 500.0, 27.393}, {2, 'K', 500.0, 20.644}, {3, 'N', 500.0, 16.748}, {4, 'R', 1000.0, 10.506},
    {5, 'S', 1000.0, 9.587}, {6, 'T', 300.0, 14.862}, {7, 'B', 1000.0, 4.834}, {8, 'E', 300.0, 21.036},
};

class TcTest : public DataLoggerTest {
 protected:
  TcTest() {
    ConfigureTcLimitsAway();
    SilenceTpdos();
  }
  // One conversion (§4: every 400 ms) and the cycle after it.
  void Convert() { Advance(400ms); }
};

// Table 1 (value column lost to OCR, list order with K = 2) and §1.2: the node turns the EMF of
// each type back into the temperature; with the cold junction at 0 C, 6130h is the NIST table's
// EMF (uV) and 6100h the temperature (0.1 C) within 0.1 C.
TEST_F(TcTest, EveryTypeMatchesNistTablePoints) {
  SetNumber("CJ.temperature_C", 0);
  for (const TypePoint& p : kPoints) {
    SCOPED_TRACE(p.letter);
    Write(0, kSensorType, 11, p.code, 2);
    SetNumber("TC1.temperature_C", p.celsius);
    Convert();
    EXPECT_NEAR(static_cast<double>(Read(0, kTcProcessValue, 1, true)), p.millivolts * 1000.0, 1.0);
    EXPECT_NEAR(static_cast<double>(Read(0, kTcFieldValue, 1, true)), p.celsius * 10.0, 1.0);
  }
}

// The conversion in both directions by itself, at NIST table points for every type (0.1 C).
TEST(TcConversion, RoundTripsNistPointsWithinATenthOfADegree) {
  for (const TypePoint& p : kPoints) {
    const auto type = TcTypeFromCode(p.code);
    ASSERT_TRUE(type.has_value());
    EXPECT_EQ(thermocouple::Letter(*type), p.letter);
    const TcReading r = ConvertThermocouple(*type, p.celsius, 0.0, true);
    EXPECT_NEAR(r.measured_mv, p.millivolts, 0.0006) << p.letter;
    EXPECT_NEAR(r.temperature_c, p.celsius, 0.1) << p.letter;
  }
  EXPECT_FALSE(TcTypeFromCode(0).has_value());
  EXPECT_FALSE(TcTypeFromCode(9).has_value());
}

// Outside NIST's inverse polynomials the reference function is solved (type K below -200 C,
// type B below 250 C), and temperatures beyond a type's table are held at its end.
TEST(TcConversion, WideRangeAndClamping) {
  using thermocouple::ThermocoupleType;
  EXPECT_NEAR(ConvertThermocouple(ThermocoupleType::kK, -250.0, 0.0, true).temperature_c, -250.0, 0.05);
  EXPECT_NEAR(ConvertThermocouple(ThermocoupleType::kB, 150.0, 0.0, true).temperature_c, 150.0, 0.05);
  EXPECT_NEAR(ConvertThermocouple(ThermocoupleType::kT, 1000.0, 0.0, true).temperature_c, 400.0, 0.05);
}

// §1.2/§3.4.19-21: the cold junction sensor gives 2161h (0.1 C) and 2162h (E(T_cj) per channel's
// type, uV); with 2160h TRUE the reading is compensated, with FALSE it is relative to the
// terminals.
TEST_F(TcTest, ColdJunctionCompensation) {
  SetNumber("CJ.temperature_C", 25);
  SetNumber("TC1.temperature_C", 500);
  Write(0, kSensorType, 12, 1, 2);  // TC2 type J
  Convert();
  EXPECT_EQ(Read(0, kTcColdJunctionPv, 0, true), 250);
  EXPECT_NEAR(static_cast<double>(Read(0, kTcColdJunctionFv, 1, true)), 1000.0, 1.0);  // K: E(25) = 1.000 mV
  EXPECT_NEAR(static_cast<double>(Read(0, kTcColdJunctionFv, 2, true)), 1277.0, 1.0);  // J: E(25) = 1.277 mV
  EXPECT_NEAR(static_cast<double>(Read(0, kTcProcessValue, 1, true)), 20644.0 - 1000.0, 1.0);
  EXPECT_NEAR(static_cast<double>(Read(0, kTcFieldValue, 1, true)), 5000.0, 1.0);

  Write(0, kTcColdJunctionEnabled, 1, 0, 1);
  Convert();
  const double uncompensated =
      *thermocouple::TemperatureFromEmf(thermocouple::ThermocoupleType::kK, 19.644) * 10.0;
  EXPECT_NEAR(static_cast<double>(Read(0, kTcFieldValue, 1, true)), uncompensated, 1.0);
  EXPECT_LT(Read(0, kTcFieldValue, 1, true), 4800);  // ~477 C: the 25 C of the terminals are missing
}

// §4: "The 4 TC inputs new measured value is available every 400 ms": a change shows at the next
// 400 ms conversion after power-on, not before.
TEST_F(TcTest, NewValuesAtTheNext400msConversion) {
  const auto before = Read(0, kTcFieldValue, 3, true);
  EXPECT_EQ(before, 250);
  Advance(360ms);  // t = 380 ms (the fixture spent 20 ms); the next conversion is at 400 ms
  SetNumber("TC3.temperature_C", 100);
  Advance(10ms);
  EXPECT_EQ(Read(0, kTcFieldValue, 3, true), 250);
  Advance(400ms);
  EXPECT_EQ(Read(0, kTcFieldValue, 3, true), 1000);
  // Both ports read the one shared object.
  EXPECT_EQ(Read(1, kTcFieldValue, 3, true), 1000);
}

// §1.2 and Table 26: an over-range ADC reading flags an open circuit, 10t0F002h (TC2: t0 = 20h),
// on both ports; 6130h/6100h read the over-range value; reconnected, the fault clears.
TEST_F(TcTest, OpenCircuitOnBothPorts) {
  SetBool("TC2.open", true);
  Convert();
  for (int port = 0; port < 2; ++port) {
    EXPECT_EQ(Frames(port, Cob(0x80u + kNodes[port])),
              std::vector<std::string>{Emcy(kNodes[port], 0xF002, 0x01, 0x20, 0x10)});
    EXPECT_EQ(ErrorField(port), std::vector<std::uint32_t>{0x1020F002});
    EXPECT_EQ(Read(port, 0x1001, 0), 1);
  }
  EXPECT_EQ(Read(0, kTcProcessValue, 2, true), 32767);
  EXPECT_EQ(Read(0, kTcFieldValue, 2, true), 32767);
  SetBool("TC2.open", false);
  Convert();
  for (int port = 0; port < 2; ++port) {
    EXPECT_EQ(Frames(port, Cob(0x80u + kNodes[port])), std::vector<std::string>{EmcyReset(kNodes[port], 0)});
    EXPECT_TRUE(ErrorField(port).empty());
  }
}

// §1.2, §3.4.22-3.4.26, Table 26: FV > 2171h sets the high warning 02t0F011h; it clears only
// once FV <= 2171h - 2174h. The 1029h sub 3 reaction applies (2 = stopped).
TEST_F(TcTest, HighWarningWithHysteresisAndErrorBehaviour) {
  Write(0, kTcHighWarning, 1, 1000, 2);  // 100.0 C
  Write(0, kTcHysteresis, 1, 50, 2);     // 5.0 C
  Write(1, 0x1029, 3, 2, 1);             // CAN2: input faults stop the node
  StartBoth();
  SetNumber("TC1.temperature_C", 101);
  Convert();
  EXPECT_EQ(Frames(0, "085#"), std::vector<std::string>{Emcy(kNode1, 0xF011, 0x01, 0x10, 0x02)});
  EXPECT_EQ(Frames(1, "086#"), std::vector<std::string>{Emcy(kNode2, 0xF011, 0x01, 0x10, 0x02)});
  EXPECT_EQ(stack(0).State(), canopen::NmtState::kOperational);  // CAN1 keeps 1029h sub 3 = 1
  EXPECT_EQ(stack(1).State(), canopen::NmtState::kStopped);

  SetNumber("TC1.temperature_C", 96);  // 96.0 > 95.0: still set
  Convert();
  EXPECT_TRUE(Frames(0, "085#").empty());
  EXPECT_EQ(ErrorField(0), std::vector<std::uint32_t>{0x0210F011});
  SetNumber("TC1.temperature_C", 95);
  Convert();
  EXPECT_EQ(Frames(0, "085#"), std::vector<std::string>{EmcyReset(kNode1, 0)});
  EXPECT_TRUE(ErrorField(0).empty());
}

// §3.4.22/3.4.24: the low limits, with their own descriptions 01h (warning) and 04h (shutdown).
TEST_F(TcTest, LowWarningAndLowShutdown) {
  Write(0, kTcLowWarning, 4, 0, 2);
  Write(0, kTcLowShutdown, 4, static_cast<std::uint16_t>(-100), 2);
  SetNumber("TC4.temperature_C", -5);
  Convert();
  EXPECT_EQ(ErrorField(0), std::vector<std::uint32_t>{0x0140F011});
  SetNumber("TC4.temperature_C", -20);
  Convert();
  EXPECT_EQ(ErrorField(0), (std::vector<std::uint32_t>{0x0440F011, 0x0140F011}));
  EXPECT_EQ(ErrorField(1), (std::vector<std::uint32_t>{0x0440F011, 0x0140F011}));
}

// §3.4.22-3.4.26: every TC limit defaults to 0, so a thermocouple at room temperature (25.0 C)
// is above the high warning and the high shutdown: the factory unit reports 02t0F011h and
// 08t0F011h for all four channels on both ports (README "Factory thresholds"), and 1003h keeps
// the 4 newest (§3.2.4).
TEST_F(DataLoggerTest, FactoryThresholdsTripAtRoomTemperature) {
  Advance(10ms);
  for (int port = 0; port < 2; ++port) {
    const auto emcys = Frames(port, Cob(0x80u + kNodes[port]));
    ASSERT_EQ(emcys.size(), 8u);
    EXPECT_EQ(emcys[0], Emcy(kNodes[port], 0xF011, 0x01, 0x10, 0x02));
    EXPECT_EQ(emcys[1], Emcy(kNodes[port], 0xF011, 0x01, 0x10, 0x08));
    EXPECT_EQ(ErrorField(port), (std::vector<std::uint32_t>{0x0840F011, 0x0240F011, 0x0830F011, 0x0230F011}));
  }
  // The demo's thresholds (README) clear every flag.
  ConfigureTcLimitsAway();
  EXPECT_TRUE(ErrorField(0).empty());
  EXPECT_TRUE(ErrorField(1).empty());
  EXPECT_EQ(Read(1, 0x1001, 0), 0);
}

// Table 13/15: a thermocouple as a control source reads 6100h against 2170h..2171h; a lookup
// table driven by TC1 shows it (data response, 3yz3h = 1 decimal like 6100h).
TEST_F(TcTest, ThermocoupleDrivesALookupTable) {
  // LT01: X = TC1 (source 4, number 1); points 0..600.0 C in steps of 60.0 C (X limits 2170h..2171h
  // = -40.0..600.0 C), Y default 0..100.
  Write(0, LutBase(1) + kLutSource, 0, 4, 1);
  Write(0, LutBase(1) + kLutNumber, 0, 1, 1);
  for (int k = 11; k >= 1; --k)
    Write(0, LutBase(1) + kLutX, static_cast<std::uint8_t>(k), static_cast<std::uint32_t>(600 * (k - 1)), 4);
  SetNumber("TC1.temperature_C", 300);
  Convert();
  EXPECT_EQ(Read(0, LutBase(1) + kLutOutput, 0, true), 50);
}

}  // namespace
}  // namespace canfleet::devices::test
