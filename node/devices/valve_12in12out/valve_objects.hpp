#pragma once
/// @file The valve controller's numbers (Axiomatic AX020411A, manual UMAX020411A V1.0.2): object
/// indexes, channel layout, enumerations and the error codes of §3.2.4 Table 33.
///
/// Channels (manual §1.1-1.5, README-dictionary.md "Conventions"): 12-entry input arrays use
/// sub-index 1-7 = universal inputs UI1-UI7 and 8-12 = digital/PWM inputs DI1-DI5; 12-entry output
/// arrays use sub-index 1-8 = proportional outputs OUT1-OUT8 and 9-12 = digital outputs DO1-DO4.
/// In this code channels are 0-based: input ch 0..11, output ch 0..11.

#include <cstdint>

namespace canfleet::devices::valve {

inline constexpr int kInputs = 12;
inline constexpr int kUniversalInputs = 7;  ///< UI1-UI7 (sub 1-7); DI1-DI5 are sub 8-12
inline constexpr int kOutputs = 12;
inline constexpr int kProportionalOutputs = 8;  ///< OUT1-OUT8 (sub 1-8); DO1-DO4 are sub 9-12
/// EMCY diagnostics exist for inputs 1-7 and outputs 1-7 only (§1.3, §1.5, §3.2.4).
inline constexpr int kDiagnosedChannels = 7;
inline constexpr int kPids = 4;
inline constexpr int kLookupTables = 12;
inline constexpr int kLogicBlocks = 4;
inline constexpr int kMathBlocks = 6;
inline constexpr int kLutPoints = 11;

inline constexpr std::uint8_t SubOf(int channel) {
  return static_cast<std::uint8_t>(channel + 1);
}

// ---- Inputs (§1.2, §1.3, §3.3.2-3.3.15, §3.4.1-3.4.18) ----
inline constexpr std::uint16_t kDiPolarity = 0x2010;
inline constexpr std::uint16_t kDiPull = 0x2020;
inline constexpr std::uint16_t kDiDebounce = 0x2030;
inline constexpr std::uint16_t kAiRange = 0x2100;
inline constexpr std::uint16_t kAiPulsesPerRev = 0x2101;
inline constexpr std::uint16_t kAiFvDigits = 0x2102;
inline constexpr std::uint16_t kAiAdcFilter = 0x2103;
inline constexpr std::uint16_t kAiErrorEnable = 0x2110;
inline constexpr std::uint16_t kAiErrorHysteresis = 0x2111;
inline constexpr std::uint16_t kAiErrorDelay = 0x2112;
inline constexpr std::uint16_t kAiFilterPower = 0x2120;
inline constexpr std::uint16_t kAiFilterIn0 = 0x2121;   ///< N0..N3 = 2121h..2124h
inline constexpr std::uint16_t kAiFilterOut1 = 0x2125;  ///< O1..O3 = 2125h..2127h
inline constexpr std::uint16_t kDiReadState = 0x6020;
inline constexpr std::uint16_t kAiSensorType = 0x6110;
inline constexpr std::uint16_t kAiMode = 0x6112;
inline constexpr std::uint16_t kAiPvDigits = 0x6132;
inline constexpr std::uint16_t kAiFilterType = 0x61A0;
inline constexpr std::uint16_t kAiFilterConstant = 0x61A1;
inline constexpr std::uint16_t kAiFieldValue = 0x7100;
inline constexpr std::uint16_t kAiScaling1Fv = 0x7120;
inline constexpr std::uint16_t kAiScaling1Pv = 0x7121;
inline constexpr std::uint16_t kAiScaling2Fv = 0x7122;
inline constexpr std::uint16_t kAiScaling2Pv = 0x7123;
inline constexpr std::uint16_t kAiProcessValue = 0x7130;
inline constexpr std::uint16_t kAiSpanStart = 0x7148;
inline constexpr std::uint16_t kAiSpanEnd = 0x7149;

/// 6110h, Table 5.
enum class SensorType : std::uint16_t {
  kVoltage = 40,
  kCurrent = 50,
  kFrequency = 60,
  kPwm = 10000,
  kResistive = 11000,
};
/// 6112h, Table 4.
enum class InputMode : std::uint8_t { kOff = 0, kNormal = 1, kDigital = 10, kAnalogOnOff = 20 };
/// 2010h, Table 3.
enum class DiPolarity : std::uint8_t { kNormal = 0, kInverse = 1, kLatched = 2 };
/// 2020h, Table 1.
enum class DiPull : std::uint8_t { kNone = 0, kPullUp = 1, kPullDown = 2 };

// ---- Outputs (§1.4, §1.5, §3.3.16-3.3.29, §3.4.19-3.4.48) ----
inline constexpr std::uint16_t kDoPolarity = 0x2210;
inline constexpr std::uint16_t kDoHotshotCurrent = 0x2220;
inline constexpr std::uint16_t kDoHoldCurrent = 0x2221;
inline constexpr std::uint16_t kDoHotshotTime = 0x2222;
inline constexpr std::uint16_t kDoBlinkRate = 0x2223;
inline constexpr std::uint16_t kDoDelayTime = 0x2224;
inline constexpr std::uint16_t kDoDelayPolarity = 0x2225;
inline constexpr std::uint16_t kAoOverrideFv = 0x2300;
inline constexpr std::uint16_t kAoErrorEnable = 0x2310;
inline constexpr std::uint16_t kAoErrorTolerance = 0x2311;  ///< "AO Error Clear Hysteresis"
inline constexpr std::uint16_t kAoErrorDelay = 0x2312;
inline constexpr std::uint16_t kAoDitherFrequency = 0x2320;  ///< sub 1 only (global)
inline constexpr std::uint16_t kAoDitherAmplitude = 0x2321;  ///< sub 1 only (global)
inline constexpr std::uint16_t kAoRampUp = 0x2330;
inline constexpr std::uint16_t kAoRampDown = 0x2331;
inline constexpr std::uint16_t kAoControlSource = 0x2340;
inline constexpr std::uint16_t kAoControlNumber = 0x2341;
inline constexpr std::uint16_t kAoControlResponse = 0x2342;
inline constexpr std::uint16_t kAoEnableSource = 0x2350;
inline constexpr std::uint16_t kAoEnableNumber = 0x2351;
inline constexpr std::uint16_t kAoEnableResponse = 0x2352;
inline constexpr std::uint16_t kAoOverrideSource = 0x2360;
inline constexpr std::uint16_t kAoOverrideNumber = 0x2361;
inline constexpr std::uint16_t kAoOverrideResponse = 0x2362;
inline constexpr std::uint16_t kAoFeedback = 0x2370;
inline constexpr std::uint16_t kAoFeedbackSamples = 0x2371;
inline constexpr std::uint16_t kAoFrequency = 0x2380;
inline constexpr std::uint16_t kDoWriteState = 0x6200;
inline constexpr std::uint16_t kDoFaultMode = 0x6250;
inline constexpr std::uint16_t kDoFaultState = 0x6260;
inline constexpr std::uint16_t kAoPvDigits = 0x6302;
inline constexpr std::uint16_t kAoType = 0x6310;
inline constexpr std::uint16_t kAoFvDigits = 0x6332;
inline constexpr std::uint16_t kAoFaultMode = 0x6340;
inline constexpr std::uint16_t kAoProcessValue = 0x7300;
inline constexpr std::uint16_t kAoScaling1Pv = 0x7320;
inline constexpr std::uint16_t kAoScaling1Fv = 0x7321;
inline constexpr std::uint16_t kAoScaling2Pv = 0x7322;
inline constexpr std::uint16_t kAoScaling2Fv = 0x7323;
inline constexpr std::uint16_t kAoFieldValue = 0x7330;
inline constexpr std::uint16_t kAoFaultFv = 0x7341;

/// 6310h, Table 14.
enum class OutputType : std::uint16_t {
  kDisabled = 0,
  kVoltage = 10,
  kCurrent = 20,
  kPwm = 40,
  kDigital = 1000,
  kHotshot = 1020,
};
inline constexpr bool IsDigitalType(std::int64_t type) {
  return type == static_cast<std::int64_t>(OutputType::kDigital) ||
         type == static_cast<std::int64_t>(OutputType::kHotshot);
}
/// 2342h, Table 18.
enum class ControlResponse : std::uint8_t { kSingle = 0, kOffBelowS1 = 1, kOffAboveS2 = 2 };
/// 2210h, Table 12.
enum class DoPolarity : std::uint8_t { kNormal = 0, kInverse = 1, kLatched = 2, kBlink = 3 };

// ---- PID (§1.6, §3.3.30-3.3.35, §3.4.49-3.4.57) ----
inline constexpr std::uint16_t kPidTolerance = 0x2450;
inline constexpr std::uint16_t kPidKi = 0x2451;
inline constexpr std::uint16_t kPidKd = 0x2452;
inline constexpr std::uint16_t kPidTargetSource = 0x2453;
inline constexpr std::uint16_t kPidTargetNumber = 0x2454;
inline constexpr std::uint16_t kPidFeedbackSource = 0x2455;
inline constexpr std::uint16_t kPidFeedbackNumber = 0x2456;
inline constexpr std::uint16_t kPidResponse = 0x2457;
inline constexpr std::uint16_t kPidOutput = 0x2460;
inline constexpr std::uint16_t kPidTimingDigits = 0x6459;
inline constexpr std::uint16_t kPidGain = 0x7450;
inline constexpr std::uint16_t kPidTi = 0x7452;
inline constexpr std::uint16_t kPidTd = 0x7454;
inline constexpr std::uint16_t kPidCycle = 0x7456;

// ---- Extra received PVs, constants (§1.10, §3.4.58-3.4.61, §3.4.98) ----
inline constexpr std::uint16_t kExtraPv = 0x2500;
inline constexpr std::uint16_t kExtraDigits = 0x2502;
inline constexpr std::uint16_t kExtraScaling1 = 0x2520;
inline constexpr std::uint16_t kExtraScaling2 = 0x2522;
inline constexpr std::uint16_t kConstant = 0x5010;

// ---- Lookup tables (§1.7, §3.4.62-3.4.70): LT yz = 1..12 at 3yz0h..3yz8h ----
inline constexpr std::uint16_t LutIndex(int table, int object) {
  // yz = 01..12 -> 301xh..312xh: the table number is the two middle hex digits in decimal.
  return static_cast<std::uint16_t>(0x3000 + ((table / 10) << 8) + ((table % 10) << 4) + object);
}

// ---- Logic blocks (§1.8, §3.4.71-3.4.84): LB1..4 = x 4..7 ----
inline constexpr std::uint16_t kLogicEnable = 0x3300;
inline constexpr std::uint16_t kLogicSelectedTable = 0x3310;
inline constexpr std::uint16_t kLogicOutput = 0x3320;
/// 3x01h (tables), 3x02h (operators), 3xYZh (function Y 1..3, condition Z 1..3).
inline constexpr std::uint16_t LogicIndex(int block, int object) {
  return static_cast<std::uint16_t>(0x3000 + ((block + 3) << 8) + object);
}
inline constexpr std::uint16_t LogicConditionIndex(int block, int function, int condition) {
  return LogicIndex(block, (function << 4) | condition);
}

// ---- Math blocks (§1.9, §3.4.85-3.4.97): Math y = 1..6 at 4y00h..4y50h ----
inline constexpr std::uint16_t kMathEnable = 0x4000;
inline constexpr std::uint16_t kMathOutScaling1 = 0x4021;
inline constexpr std::uint16_t kMathOutScaling2 = 0x4023;
inline constexpr std::uint16_t kMathOutput = 0x4030;
inline constexpr std::uint16_t kMathOutDigits = 0x4032;
inline constexpr std::uint16_t MathIndex(int block, int object) {
  return static_cast<std::uint16_t>(0x4000 + (block << 8) + object);
}
inline constexpr std::uint16_t kMathInSource = 0x00;
inline constexpr std::uint16_t kMathInNumber = 0x01;
inline constexpr std::uint16_t kMathInFunction = 0x02;
inline constexpr std::uint16_t kMathInDigits = 0x03;
inline constexpr std::uint16_t kMathInScaling1 = 0x20;
inline constexpr std::uint16_t kMathInScaling2 = 0x22;
inline constexpr std::uint16_t kMathInGain = 0x40;
inline constexpr std::uint16_t kMathOperator = 0x50;

// ---- Supply and temperature (§1.10, §3.4.99-3.4.107), start-up (§3.4.108-3.4.111) ----
inline constexpr std::uint16_t kSupplyVoltage = 0x5020;
inline constexpr std::uint16_t kSupplyEnable = 0x5021;
inline constexpr std::uint16_t kSupplyUnder = 0x5022;
inline constexpr std::uint16_t kSupplyOver = 0x5023;
inline constexpr std::uint16_t kSupplyHysteresis = 0x5024;
inline constexpr std::uint16_t kTemperature = 0x5030;
inline constexpr std::uint16_t kTemperatureEnable = 0x5031;
inline constexpr std::uint16_t kTemperatureOver = 0x5032;
inline constexpr std::uint16_t kTemperatureHysteresis = 0x5033;
inline constexpr std::uint16_t kAutoUpdate = 0x5550;
inline constexpr std::uint16_t kStartOperational = 0x5555;
inline constexpr std::uint16_t kChangeBaudRate = 0x5B50;  ///< §3.4.110, Table 32 indexes

// ---- Errors (§3.2.4 Table 33): 1003h = description << 24 | channel << 16 | EMCY code ----
inline constexpr std::uint16_t kEmcyInputOverload = 0xF001;   ///< AI out of range
inline constexpr std::uint16_t kEmcyOutputOverload = 0xF002;  ///< AO open circuit
inline constexpr std::uint16_t kEmcyVoltage = 0x3000;         ///< supply over/under voltage
/// Over-temperature: not in Table 33 (§4 "Diagnostics" says it is reported). CiA 301's 4200h
/// "device temperature" with the family's "positive overload" description: 20004200h (README).
inline constexpr std::uint16_t kEmcyTemperature = 0x4200;
inline constexpr std::uint8_t kDescPositiveOverload = 0x20;  ///< out of range high, over voltage
inline constexpr std::uint8_t kDescNegativeOverload = 0x40;  ///< out of range low, under voltage
inline constexpr std::uint8_t kDescSensorBreak = 0x10;       ///< open circuit on an output

/// 1029h sub-indexes (§3.2.13).
inline constexpr std::uint8_t kBehaviourCommunication = 1;
inline constexpr std::uint8_t kBehaviourDigitalInput = 2;
inline constexpr std::uint8_t kBehaviourAnalogInput = 3;
inline constexpr std::uint8_t kBehaviourDigitalOutput = 4;
inline constexpr std::uint8_t kBehaviourAnalogOutput = 5;

}  // namespace canfleet::devices::valve
