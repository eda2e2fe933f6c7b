#pragma once
/// @file Object indexes of the Axiomatic Data Logger AX181001 (user manual UMAX181001 V1.01, §3.2-§3.4)
/// that its function blocks read and write, and the numbering of its channels. The dictionary
/// itself is datalogger-tc-analog.od (this folder).

#include <cstdint>

namespace canfleet::devices::datalogger {

inline constexpr int kThermocouples = 4;    ///< TC1-TC4 (§1.2)
inline constexpr int kAnalogInputs = 10;    ///< AI1-AI7 analog, AI8-AI10 universal (§1.1)
inline constexpr int kFirstUniversal = 8;   ///< inputs 8-10 can be digital (§1.3)
inline constexpr int kReceivedValues = 12;  ///< 2500h sub 1-12 (§1.8)
inline constexpr int kConstants = 15;       ///< 5010h sub 1-15
inline constexpr int kLookupTables = 12;    ///< LT01-LT12 (§1.5)
inline constexpr int kLogicBlocks = 4;      ///< LB1-LB4 (§1.6)
inline constexpr int kMathBlocks = 6;       ///< Math 1-6 (§1.7)
inline constexpr int kMathInputs = 6;
inline constexpr int kMathFunctions = 3;

// ---- Digital input (§1.3, §3.3.1, §3.4.1-3.4.3) ---------------------------------------------
inline constexpr std::uint16_t kDiPolarity = 0x2010;
inline constexpr std::uint16_t kDiPullup = 0x2020;
inline constexpr std::uint16_t kDiDebounce = 0x2030;
inline constexpr std::uint16_t kDiState = 0x6020;

// ---- Analog input (§1.4, §3.3.4-3.3.16, §3.4.4-3.4.18) --------------------------------------
inline constexpr std::uint16_t kAiRange = 0x2100;
inline constexpr std::uint16_t kAiPulsesPerRev = 0x2101;
inline constexpr std::uint16_t kAiFvDigits = 0x2102;
inline constexpr std::uint16_t kAiAdcFilter = 0x2103;
inline constexpr std::uint16_t kAiErrorEnable = 0x2110;
inline constexpr std::uint16_t kAiErrorHysteresis = 0x2111;
inline constexpr std::uint16_t kAiErrorDelay = 0x2112;
inline constexpr std::uint16_t kAiFilterPower = 0x2120;
inline constexpr std::uint16_t kAiFilterInput0 = 0x2121;   ///< N0..N3 = 2121h..2124h
inline constexpr std::uint16_t kAiFilterOutput1 = 0x2125;  ///< O1..O3 = 2125h..2127h
inline constexpr std::uint16_t kSensorType = 0x6110;       ///< subs 1-10 AI, 11-14 TC type
inline constexpr std::uint16_t kAiOperatingMode = 0x6112;
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

/// 6110h values (Table 6).
enum SensorType : std::uint16_t {
  kSensorVoltage = 40,
  kSensorCurrent = 50,
  kSensorFrequency = 60,
  kSensorPwm = 10000,
};
/// 6112h values (Table 5).
enum OperatingMode : std::uint8_t {
  kModeOff = 0,
  kModeNormal = 1,
  kModeDigital = 10,
  kModeAnalogOnOff = 20,
};

// ---- Thermocouple (§1.2, §3.3.2-3.3.4, §3.4.19-3.4.26) --------------------------------------
inline constexpr std::uint8_t kTcTypeSubOffset = 10;  ///< 6110h sub 11-14 = TC1-TC4
inline constexpr std::uint16_t kTcColdJunctionEnabled = 0x2160;
inline constexpr std::uint16_t kTcColdJunctionPv = 0x2161;
inline constexpr std::uint16_t kTcColdJunctionFv = 0x2162;
inline constexpr std::uint16_t kTcLowWarning = 0x2170;
inline constexpr std::uint16_t kTcHighWarning = 0x2171;
inline constexpr std::uint16_t kTcLowShutdown = 0x2172;
inline constexpr std::uint16_t kTcHighShutdown = 0x2173;
inline constexpr std::uint16_t kTcHysteresis = 0x2174;
inline constexpr std::uint16_t kTcFieldValue = 0x6100;
inline constexpr std::uint16_t kTcProcessValue = 0x6130;

// ---- Extra received values, constants, diagnostics, start-up (§1.8, §3.4.27-3.4.80) ---------
inline constexpr std::uint16_t kReceivedPv = 0x2500;
inline constexpr std::uint16_t kReceivedDigits = 0x2502;
inline constexpr std::uint16_t kReceivedScaling1 = 0x2520;
inline constexpr std::uint16_t kReceivedScaling2 = 0x2522;
inline constexpr std::uint16_t kConstantValue = 0x5010;
inline constexpr std::uint16_t kSupplyValue = 0x5020;
inline constexpr std::uint16_t kSupplyErrorEnable = 0x5021;
inline constexpr std::uint16_t kUnderVoltage = 0x5022;
inline constexpr std::uint16_t kOverVoltage = 0x5023;
inline constexpr std::uint16_t kSupplyHysteresis = 0x5024;
inline constexpr std::uint16_t kCpuTemperature = 0x5030;
inline constexpr std::uint16_t kCpuTemperatureEnable = 0x5031;
inline constexpr std::uint16_t kOverTemperature = 0x5032;
inline constexpr std::uint16_t kCpuTemperatureHysteresis = 0x5033;
inline constexpr std::uint16_t kAutoUpdates = 0x5550;
inline constexpr std::uint16_t kStartOperational = 0x5555;  ///< sub 1 CAN1, sub 2 CAN2
inline constexpr std::uint16_t kChangeBaudRate = 0x5B50;
inline constexpr std::uint16_t kChangeNodeId = 0x5B51;

// ---- Lookup tables LT01-LT12 (§1.5, §3.4.31-3.4.39): 3yz0h-3yz8h, yz = 01..12 -------------------
/// 3yz0h of table `table` (1..12): LT01 = 3010h, LT09 = 3090h, LT10 = 3100h, LT12 = 3120h.
constexpr std::uint16_t LutBase(int table) {
  return static_cast<std::uint16_t>(0x3000 + (table / 10) * 0x100 + (table % 10) * 0x10);
}
inline constexpr std::uint16_t kLutSource = 0x0;
inline constexpr std::uint16_t kLutNumber = 0x1;
inline constexpr std::uint16_t kLutAutoRepeat = 0x2;
inline constexpr std::uint16_t kLutXDigits = 0x3;
inline constexpr std::uint16_t kLutYDigits = 0x4;
inline constexpr std::uint16_t kLutResponse = 0x5;  ///< sub 1 X-axis type, subs 2-11 point responses
inline constexpr std::uint16_t kLutX = 0x6;
inline constexpr std::uint16_t kLutY = 0x7;
inline constexpr std::uint16_t kLutOutput = 0x8;
inline constexpr int kLutPoints = 11;

// ---- Logic blocks LB1-LB4 (§1.6, §3.4.40-3.4.53): 3x01h-3x33h, x = block + 3 ---------------------
inline constexpr std::uint16_t kLogicEnable = 0x3300;
inline constexpr std::uint16_t kLogicSelectedTable = 0x3310;
inline constexpr std::uint16_t kLogicOutput = 0x3320;
/// 3x00h of logic block `block` (1..4): LB1 = 3400h.
constexpr std::uint16_t LogicBase(int block) {
  return static_cast<std::uint16_t>(0x3000 + (block + 3) * 0x100);
}
inline constexpr std::uint16_t kLogicTables = 0x01;     ///< 3x01h sub 1-3 = tables A-C
inline constexpr std::uint16_t kLogicOperators = 0x02;  ///< 3x02h sub 1-3
/// 3xyzh: function f (1 = A .. 3 = C), condition c (1..3).
constexpr std::uint16_t LogicCondition(int block, int function, int condition) {
  return static_cast<std::uint16_t>(LogicBase(block) + function * 0x10 + condition);
}

// ---- Math blocks 1-6 (§1.7, §3.4.54-3.4.66) ----------------------------------------------------
inline constexpr std::uint16_t kMathEnable = 0x4000;
inline constexpr std::uint16_t kMathOutputScaling1 = 0x4021;
inline constexpr std::uint16_t kMathOutputScaling2 = 0x4023;
inline constexpr std::uint16_t kMathOutput = 0x4030;
inline constexpr std::uint16_t kMathOutputDigits = 0x4032;
/// 4y00h of math block `block` (1..6).
constexpr std::uint16_t MathBase(int block) {
  return static_cast<std::uint16_t>(0x4000 + block * 0x100);
}
inline constexpr std::uint16_t kMathSource = 0x00;
inline constexpr std::uint16_t kMathNumber = 0x01;
inline constexpr std::uint16_t kMathFunctionNumber = 0x02;
inline constexpr std::uint16_t kMathInputDigits = 0x03;
inline constexpr std::uint16_t kMathInputScaling1 = 0x20;
inline constexpr std::uint16_t kMathInputScaling2 = 0x22;
inline constexpr std::uint16_t kMathGain = 0x40;
inline constexpr std::uint16_t kMathOperator = 0x50;

// ---- Emergency codes and 1003h descriptions (§3.2.4 Table 26) ------------------------------------
inline constexpr std::uint16_t kEmcyInputOverload = 0xF001;  ///< AI out of span
inline constexpr std::uint16_t kEmcyTcOverload = 0xF002;     ///< TC open circuit
inline constexpr std::uint16_t kEmcyTcLimit = 0xF011;        ///< TC warning/shutdown limit
inline constexpr std::uint16_t kEmcyVoltage = 0x3000;        ///< supply over/under voltage
/// Processor over-temperature: Table 26 has no code; CiA 301 "device temperature" (README choice).
inline constexpr std::uint16_t kEmcyDeviceTemperature = 0x4200;
inline constexpr std::uint8_t kDescPositiveOverload = 0x20;
inline constexpr std::uint8_t kDescNegativeOverload = 0x40;
inline constexpr std::uint8_t kDescTcLowWarning = 0x01;
inline constexpr std::uint8_t kDescTcHighWarning = 0x02;
inline constexpr std::uint8_t kDescTcLowShutdown = 0x04;
inline constexpr std::uint8_t kDescTcHighShutdown = 0x08;
inline constexpr std::uint8_t kDescTcOpen = 0x10;
/// 1029h sub-index of "Analog Input Fault (AI & TC)" (§3.2.13).
inline constexpr std::uint8_t kBehaviourInputFault = 3;

/// 1-based sub-index of 0-based channel `ch`.
constexpr std::uint8_t SubOf(int ch) {
  return static_cast<std::uint8_t>(ch + 1);
}

}  // namespace canfleet::devices::datalogger
