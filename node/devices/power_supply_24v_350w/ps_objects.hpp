#pragma once
/// @file The power supply's numbers (manual UMAX080311 V1.0.3): object indexes, command values,
/// the 2-bit flag layout of the CiA 453 failure-status objects and the error codes of Table 9.

#include <cstdint>

namespace canfleet::devices::ps {

// Manufacturer objects (§2.4).
inline constexpr std::uint16_t kInputFilterType = 0x2100;      ///< §2.4.1, sub 1
inline constexpr std::uint16_t kInputFilterConstant = 0x2101;  ///< §2.4.2, sub 1
inline constexpr std::uint16_t kShutdownAck = 0x2301;          ///< §2.4.4
inline constexpr std::uint16_t kBaseShutdownDelay = 0x2302;    ///< §2.4.5, ms
inline constexpr std::uint16_t kAckShutdownDelay = 0x2303;     ///< §2.4.6, ms
inline constexpr std::uint16_t kEnableDeglitch = 0x2310;       ///< §2.4.7, ms
inline constexpr std::uint16_t kSleepDelay = 0x2311;           ///< §2.4.8, ms (0 = no sleep)
inline constexpr std::uint16_t kEnableDs453Fault = 0x2320;     ///< §2.4.9, 1 = latch until Quit Failure
inline constexpr std::uint16_t kCurrentLimitControl = 0x2330;  ///< §2.4.10, 0 = Fig. 2, 1 = 6205h.8
inline constexpr std::uint16_t kReceivedPv = 0x2500;           ///< §2.4.11
inline constexpr std::uint16_t kScaling1 = 0x2520;             ///< §2.4.13
inline constexpr std::uint16_t kScaling2 = 0x2522;             ///< §2.4.14
inline constexpr std::uint16_t kStartInOperational = 0x5555;   ///< §2.4.17
inline constexpr std::uint16_t kChangeBaudRate = 0x5B50;       ///< §2.4 table only
inline constexpr std::uint16_t kChangeNodeId = 0x5B51;         ///< §2.4 table only

// CiA 453 objects (§2.3).
inline constexpr std::uint16_t kGeneralCommands = 0x6010;    ///< .1 control mode, .2 quit failure
inline constexpr std::uint16_t kDeviceStatus = 0x6011;       ///< .1 condition (TPDO1)
inline constexpr std::uint16_t kDeviceFailure = 0x6012;      ///< §2.3.2
inline constexpr std::uint16_t kDeviceStatusDelay = 0x6013;  ///< §2.3.3 .1 input, .2 output, ms
inline constexpr std::uint16_t kTemperature = 0x6020;        ///< §2.3.4, 0.1 degC
inline constexpr std::uint16_t kTemperatureThreshold1 = 0x6021;
inline constexpr std::uint16_t kTemperatureThreshold2 = 0x6022;
inline constexpr std::uint16_t kTemperatureReturn1 = 0x6025;
inline constexpr std::uint16_t kTemperatureReturn2 = 0x6026;
inline constexpr std::uint16_t kInputFailure = 0x6112;  ///< §2.3.9
inline constexpr std::uint16_t kInputActual = 0x6113;   ///< §2.3.10 .1 mV
inline constexpr std::uint16_t kInputThreshold1 = 0x6114;
inline constexpr std::uint16_t kInputThreshold2 = 0x6115;
inline constexpr std::uint16_t kInputFailureDelay = 0x6119;  ///< §2.3.13 .1 .2 .9 .10, ms
inline constexpr std::uint16_t kInputReturn1 = 0x611A;
inline constexpr std::uint16_t kInputReturn2 = 0x611B;
inline constexpr std::uint16_t kOutputCommands = 0x6200;   ///< §2.3.16 .2 on/off, .3 quit failure
inline constexpr std::uint16_t kOutputStatus = 0x6201;     ///< .1 condition
inline constexpr std::uint16_t kOutputFailure = 0x6202;    ///< §2.3.17
inline constexpr std::uint16_t kOutputRanges = 0x6203;     ///< §2.3.18
inline constexpr std::uint16_t kOutputActual = 0x6204;     ///< §2.3.19 .1 mV, .2 mA
inline constexpr std::uint16_t kOutputSetValues = 0x6205;  ///< §2.3.20

// 6205h sub-indexes (§2.3.20, Table 5).
inline constexpr std::uint8_t kSetVoltage = 1;
inline constexpr std::uint8_t kMaxVoltage = 2;
inline constexpr std::uint8_t kMinVoltage = 3;
inline constexpr std::uint8_t kVoltageThreshold1 = 4;
inline constexpr std::uint8_t kVoltageThreshold2 = 5;
inline constexpr std::uint8_t kVoltageDelay1 = 6;
inline constexpr std::uint8_t kVoltageDelay2 = 7;
inline constexpr std::uint8_t kSetCurrent = 8;
inline constexpr std::uint8_t kMaxCurrent = 9;
inline constexpr std::uint8_t kCurrentThreshold1 = 11;
inline constexpr std::uint8_t kCurrentThreshold2 = 12;
inline constexpr std::uint8_t kCurrentDelay1 = 13;
inline constexpr std::uint8_t kCurrentDelay2 = 14;
inline constexpr std::uint8_t kVoltageReturn1 = 39;
inline constexpr std::uint8_t kVoltageReturn2 = 40;
inline constexpr std::uint8_t kCurrentReturn1 = 41;
inline constexpr std::uint8_t kCurrentReturn2 = 42;

// Command values (§1.2.1 Tables 1, 2 and 6; §2.3.1, §2.3.16).
inline constexpr std::uint8_t kCommandOff = 0xFC;  ///< 6200h.2 switch off; 6200h.3/6010h.2 quit failure
inline constexpr std::uint8_t kCommandOn = 0xFD;   ///< 6200h.2 switch on
inline constexpr std::uint8_t kNoAction = 0xFF;
inline constexpr std::uint8_t kQuitFailure = 0xFC;
/// 6010h.1 (Table 1): the Enable pin, 6200h.2, or whichever changed last.
inline constexpr std::uint8_t kControlLocal = 0xFC;
inline constexpr std::uint8_t kControlRemote = 0xFD;
inline constexpr std::uint8_t kControlBoth = 0xFF;

// Sub-indexes of the failure-status objects 6012h, 6112h, 6202h (§2.3.2, §2.3.9, §2.3.17).
inline constexpr std::uint8_t kCondition = 1;
inline constexpr std::uint8_t kLogic = 2;
inline constexpr std::uint8_t kEvent = 3;
inline constexpr std::uint8_t kFaultState = 4;
inline constexpr std::uint8_t kIndication = 5;

// 2-bit flag positions (the shift of the flag's low bit).
inline constexpr unsigned kFlagVt1 = 0;     ///< 6112h/6202h voltage threshold 1
inline constexpr unsigned kFlagVt2 = 2;     ///< 6112h/6202h voltage threshold 2
inline constexpr unsigned kFlagCt1 = 4;     ///< 6202h current threshold 1
inline constexpr unsigned kFlagCt2 = 6;     ///< 6202h current threshold 2
inline constexpr unsigned kFlagTt1 = 16;    ///< 6112h temperature threshold 1
inline constexpr unsigned kFlagTt2 = 18;    ///< 6112h temperature threshold 2
inline constexpr unsigned kFlagInput = 0;   ///< 6012h "i" input failure
inline constexpr unsigned kFlagOutput = 2;  ///< 6012h "o1" output failure

// Flag values: condition/logic 00 "lower than return", 01 "higher or equal than threshold",
// 10 error, 11 N/A; event/indication 00 off, 01 on; fault state 01 process, 11 ignore.
inline constexpr std::uint32_t kFlagLow = 0b00;
inline constexpr std::uint32_t kFlagHigh = 0b01;
inline constexpr std::uint32_t kFlagOff = 0b00;
inline constexpr std::uint32_t kFlagOn = 0b01;
inline constexpr std::uint32_t kFlagProcess = 0b01;

// Table 9 (§2.2.4): EMCY codes and the description byte of the 1003h entry.
inline constexpr std::uint16_t kEmcyInputFailure = 0xFF04;
inline constexpr std::uint16_t kEmcyOutputFailure = 0xFF06;
inline constexpr std::uint16_t kEmcyShutdown = 0xF001;
inline constexpr std::uint8_t kDescriptionShutdown = 0x20;

// 1029h sub-indexes (§2.2.13).
inline constexpr std::uint8_t kBehaviourInput = 3;
inline constexpr std::uint8_t kBehaviourOutput = 4;

}  // namespace canfleet::devices::ps
