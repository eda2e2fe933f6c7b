#pragma once
/// @file The objects of the AX023241 encoder dual valve controller the behaviour uses (indexes
/// from encoder-dual-valve.od, which cites the manual's sections), its channel counts and the
/// EMCY codes chosen for it (README.md, "EMCY codes": the manual defines none).
///
/// Section numbers: chapter 3 of the manual prints its subsections as 1.x; they are cited as
/// C3-1.x (C3-1.3.22 = 6310h). Plain numbers are chapter 1 (1.4 = output drives).

#include <cstdint>

namespace canfleet::devices::encoder {

inline constexpr int kInputs = 2;   ///< 1.2: two digital inputs (QA/QB of the encoder)
inline constexpr int kOutputs = 2;  ///< 1.4: two universal high-side outputs
inline constexpr int kLookupTables = 2;
inline constexpr int kMathBlocks = 2;
inline constexpr int kMathInputs = 5;
inline constexpr int kMathOperators = 4;
inline constexpr int kLutPoints = 11;  ///< X0..X10 (1.6.1)

/// Sub-index of channel `ch` (0-based) in the two-channel arrays.
constexpr std::uint8_t SubOf(int ch) {
  return static_cast<std::uint8_t>(ch + 1);
}

// ---- DS-404 application objects (C3-1.3) ----------------------------------------------------
inline constexpr std::uint16_t kDiReadState = 0x6000;
inline constexpr std::uint16_t kDiPolarity = 0x6002;
inline constexpr std::uint16_t kAiSensorType = 0x6110;
inline constexpr std::uint16_t kAiOperatingMode = 0x6112;
inline constexpr std::uint16_t kAiFilterType = 0x61A0;
inline constexpr std::uint16_t kAiFilterConstant = 0x61A1;
inline constexpr std::uint16_t kDoWriteState = 0x6200;
inline constexpr std::uint16_t kDoPolarity = 0x6202;
inline constexpr std::uint16_t kDoFaultMode = 0x6250;
inline constexpr std::uint16_t kDoFaultState = 0x6260;
inline constexpr std::uint16_t kAoPvDigits = 0x6302;
inline constexpr std::uint16_t kAoOutputType = 0x6310;
inline constexpr std::uint16_t kAoFvDigits = 0x6332;
inline constexpr std::uint16_t kAoFaultMode = 0x6340;
inline constexpr std::uint16_t kPidTimingDigits = 0x6459;
inline constexpr std::uint16_t kAiFieldValue = 0x7100;
inline constexpr std::uint16_t kAiScaling1Fv = 0x7120;
inline constexpr std::uint16_t kAiScaling1Pv = 0x7121;
inline constexpr std::uint16_t kAiScaling2Fv = 0x7122;
inline constexpr std::uint16_t kAiScaling2Pv = 0x7123;
inline constexpr std::uint16_t kAiProcessValue = 0x7130;
inline constexpr std::uint16_t kAiSpanStart = 0x7148;
inline constexpr std::uint16_t kAiSpanEnd = 0x7149;
inline constexpr std::uint16_t kAoProcessValue = 0x7300;
inline constexpr std::uint16_t kAoScaling1Pv = 0x7320;
inline constexpr std::uint16_t kAoScaling1Fv = 0x7321;
inline constexpr std::uint16_t kAoScaling2Pv = 0x7322;
inline constexpr std::uint16_t kAoScaling2Fv = 0x7323;
inline constexpr std::uint16_t kAoFieldValue = 0x7330;
inline constexpr std::uint16_t kAoFaultFv = 0x7341;
inline constexpr std::uint16_t kPidProportionalBand = 0x7450;
inline constexpr std::uint16_t kPidIntegralTime = 0x7452;
inline constexpr std::uint16_t kPidDerivativeTime = 0x7454;
inline constexpr std::uint16_t kPidCycleTime = 0x7456;

// ---- manufacturer objects (C3-1.4) ----------------------------------------------------------
inline constexpr std::uint16_t kDiPull = 0x2020;
inline constexpr std::uint16_t kAiRange = 0x2100;
inline constexpr std::uint16_t kAiFvDigits = 0x2102;
inline constexpr std::uint16_t kAiErrorEnable = 0x2110;
inline constexpr std::uint16_t kAiErrorHysteresis = 0x2111;
inline constexpr std::uint16_t kAiErrorDelay = 0x2112;
inline constexpr std::uint16_t kDoDelayTime = 0x2224;
inline constexpr std::uint16_t kDoDelayPolarity = 0x2225;
inline constexpr std::uint16_t kAoOverrideFv = 0x2300;
inline constexpr std::uint16_t kAoErrorEnable = 0x2310;
inline constexpr std::uint16_t kAoErrorHysteresis = 0x2311;
inline constexpr std::uint16_t kAoErrorDelay = 0x2312;
inline constexpr std::uint16_t kAoRampUp = 0x2330;
inline constexpr std::uint16_t kAoRampDown = 0x2331;
inline constexpr std::uint16_t kAoControlSource = 0x2340;
inline constexpr std::uint16_t kAoControlNumber = 0x2341;
inline constexpr std::uint16_t kAoEnableSource = 0x2350;
inline constexpr std::uint16_t kAoEnableNumber = 0x2351;
inline constexpr std::uint16_t kAoOverrideSource = 0x2360;
inline constexpr std::uint16_t kAoOverrideNumber = 0x2361;
inline constexpr std::uint16_t kAoOverrideResponse = 0x2362;
inline constexpr std::uint16_t kAoFeedback = 0x2370;
inline constexpr std::uint16_t kAoFrequency = 0x2380;
inline constexpr std::uint16_t kPidTolerance = 0x2450;
inline constexpr std::uint16_t kPidIntegralGain = 0x2451;
inline constexpr std::uint16_t kPidDerivativeGain = 0x2452;
inline constexpr std::uint16_t kPidTargetSource = 0x2453;
inline constexpr std::uint16_t kPidTargetNumber = 0x2454;
inline constexpr std::uint16_t kPidFeedbackSource = 0x2455;
inline constexpr std::uint16_t kPidFeedbackNumber = 0x2456;
inline constexpr std::uint16_t kPidResponse = 0x2457;
inline constexpr std::uint16_t kPidOutput = 0x2460;
inline constexpr std::uint16_t kEcValue = 0x2500;
inline constexpr std::uint16_t kEcDigits = 0x2502;
inline constexpr std::uint16_t kEcScaling1 = 0x2520;
inline constexpr std::uint16_t kEcScaling2 = 0x2522;
inline constexpr std::uint16_t kQdScaler = 0x3410;
inline constexpr std::uint16_t kQdDirection = 0x3411;
inline constexpr std::uint16_t kQdOffset = 0x3412;
inline constexpr std::uint16_t kQdPulsesPerRev = 0x3413;
inline constexpr std::uint16_t kMathEnable = 0x4000;
inline constexpr std::uint16_t kMathOutScaling1 = 0x4021;
inline constexpr std::uint16_t kMathOutScaling2 = 0x4023;
inline constexpr std::uint16_t kMathOutput = 0x4030;
inline constexpr std::uint16_t kMathOutDigits = 0x4032;
inline constexpr std::uint16_t kConstants = 0x5010;
inline constexpr std::uint16_t kSupplyVoltage = 0x5020;
inline constexpr std::uint16_t kCpuTemperature = 0x5030;
inline constexpr std::uint16_t kFdFieldValue = 0x5040;
inline constexpr std::uint16_t kFdSetThreshold = 0x5041;
inline constexpr std::uint16_t kFdClearThreshold = 0x5042;
inline constexpr std::uint16_t kFdEnable = 0x5050;
inline constexpr std::uint16_t kFdDelay = 0x5051;
inline constexpr std::uint16_t kStartInOperational = 0x5555;
inline constexpr std::uint16_t kStartNmtDelay = 0x5556;

/// Lookup table `table` (1..2) object `k` (0..8): 30x0h..30x8h with x = table (README-dictionary 32).
constexpr std::uint16_t LutIndex(int table, int k) {
  return static_cast<std::uint16_t>(0x3000 + 0x10 * table + k);
}
inline constexpr int kLutSource = 0, kLutNumber = 1, kLutAutoRepeat = 2, kLutXDigits = 3, kLutYDigits = 4,
                     kLutResponse = 5, kLutX = 6, kLutY = 7, kLutOutput = 8;

/// Math block `block` (1..2) input object `k`: 4x00h..4x50h with x = block (README-dictionary 35).
constexpr std::uint16_t MathIndex(int block, int k) {
  return static_cast<std::uint16_t>(0x4000 + 0x100 * block + k);
}
inline constexpr int kMathSource = 0x00, kMathNumber = 0x01, kMathDigits = 0x03, kMathScaling1 = 0x20,
                     kMathScaling2 = 0x22, kMathGain = 0x40, kMathOperator = 0x50;

// ---- enumerations ---------------------------------------------------------------------------
/// 6110h, Table 1.
enum class SensorType : std::uint16_t { kFrequency = 60, kPwm = 10000, kQuadrature = 10002 };
/// 6112h, Table 2 (1 is the printed default: DS-404 "normal operation", README choice).
enum class OperatingMode : std::uint8_t { kOff = 0, kNormal = 1, kDigital = 10 };
/// 2100h for a quadrature input, Table 3.
enum class QuadratureRange : std::uint8_t { kCount = 0, kDirection = 1, kSpeed = 2 };
/// 2100h for a digital input, Table 3.
enum class DigitalRange : std::uint8_t { kNormal = 0, kInverse = 1, kLatched = 2 };
/// 6310h, Table 8.
enum class OutputType : std::uint16_t {
  kDisabled = 0,
  kVoltage = 10,
  kCurrent = 20,
  kPwm = 40,
  kDigital = 1000,
  kHotshot = 1020,
};
/// 2020h, Table 4.
enum class PullMode : std::uint8_t { kNone = 0, kPullUp = 1, kPullDown = 2 };

// ---- 1029h sub-indexes (C3-1.2.11) ----------------------------------------------------------
inline constexpr std::uint8_t kBehaviourCommunication = 1;
inline constexpr std::uint8_t kBehaviourDigitalInput = 2;
inline constexpr std::uint8_t kBehaviourAnalogInput = 3;
inline constexpr std::uint8_t kBehaviourDigitalOutput = 4;
inline constexpr std::uint8_t kBehaviourAnalogOutput = 5;
inline constexpr std::uint8_t kBehaviourOther = 6;

// ---- EMCY codes: the family's (README.md "EMCY codes") --------------------------------------
// 1003h entry = description << 24 | channel << 16 | code, as the valve, power supply and data
// logger tables print them (family_error_policy.hpp).
inline constexpr std::uint16_t kEmcyInput = 0xF001;        ///< valve/logger "input out of range"
inline constexpr std::uint16_t kEmcyOutput = 0xF002;       ///< valve/logger "output open circuit"
inline constexpr std::uint16_t kEmcyVoltage = 0x3000;      ///< valve/logger supply over/under voltage
inline constexpr std::uint16_t kEmcyTemperature = 0x4200;  ///< CiA 301 "device temperature"
inline constexpr std::uint8_t kDescHigh = 0x20;            ///< above the limit (valve 20nnF001h)
inline constexpr std::uint8_t kDescLow = 0x40;             ///< below the limit (valve 40nnF001h)
inline constexpr std::uint8_t kDescOpen = 0x10;            ///< open circuit (valve 10nnF002h)
inline constexpr std::uint8_t kDescShort = 0x20;           ///< short circuit / over-current

}  // namespace canfleet::devices::encoder
