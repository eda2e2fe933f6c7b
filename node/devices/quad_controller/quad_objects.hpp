#pragma once
/// @file The Quad controller's numbers (manual AX020506 V2.02): object indexes, channel layout,
/// enumerations and the error codes of §4.1.
///
/// Channels: per-input objects use sub-index 1-4 = AIN1-AIN4 and 5-6 = FIN1-FIN2; 8-line input
/// objects use bit 0-5 in the same order (§2.2, §2.3). Per-output objects use sub-index 1-4 =
/// POUT1-POUT4; DO objects add sub-index 5 / bit 4 = DOUT (§2.5). In this code channels are
/// 0-based: input ch 0..5, output 0..4.

#include <array>
#include <cstdint>

#include "node/canopen/emcy/error_entry.hpp"

namespace canfleet::devices::quad {

inline constexpr int kInputs = 6;          ///< AIN1-4, FIN1-2
inline constexpr int kAnalogInputs = 4;    ///< AIN1-4 (the rest are FIN)
inline constexpr int kPouts = 4;           ///< POUT1-4
inline constexpr int kDigitalOutputs = 5;  ///< POUT1-4 configured as DO, and DOUT
inline constexpr int kDout = 4;            ///< DOUT's DO channel (sub-index 5, bit 4)

inline constexpr std::uint8_t SubOf(int channel) {
  return static_cast<std::uint8_t>(channel + 1);
}

// Objects (§3.2-§3.5, §3.1.10).
inline constexpr std::uint16_t kDiLevel = 0x2000;
inline constexpr std::uint16_t kDiLowThreshold = 0x2001;
inline constexpr std::uint16_t kDiHighThreshold = 0x2002;
inline constexpr std::uint16_t kAiErrorMinimum = 0x2010;
inline constexpr std::uint16_t kAiMinimum = 0x2020;
inline constexpr std::uint16_t kAiBreakpointMinimum = 0x2030;
inline constexpr std::uint16_t kAiDeadbandMinimum = 0x2040;
inline constexpr std::uint16_t kAiDeadbandMaximum = 0x2050;
inline constexpr std::uint16_t kAiBreakpointMaximum = 0x2060;
inline constexpr std::uint16_t kAiMaximum = 0x2070;
inline constexpr std::uint16_t kAiErrorMaximum = 0x2080;
inline constexpr std::uint16_t kAiFrequencyWindow = 0x2090;
inline constexpr std::uint16_t kAiErrorCheckEnable = 0x20A0;
inline constexpr std::uint16_t kAiErrorDelay = 0x20B0;
inline constexpr std::uint16_t kDoControlInput = 0x3001;
inline constexpr std::uint16_t kDoResponse = 0x3002;
inline constexpr std::uint16_t kDoErrorDelay = 0x300B;
inline constexpr std::uint16_t kDoReadState = 0x300C;
inline constexpr std::uint16_t kAoControlInput = 0x3010;
inline constexpr std::uint16_t kAoResponse = 0x3020;
inline constexpr std::uint16_t kAoMinimumCurrent = 0x3030;
inline constexpr std::uint16_t kAoBreakpointCurrent = 0x3040;
inline constexpr std::uint16_t kAoMaximumCurrent = 0x3050;
inline constexpr std::uint16_t kAoDitherFrequency = 0x3060;
inline constexpr std::uint16_t kAoDitherAmplitude = 0x3070;
inline constexpr std::uint16_t kAoRampUp = 0x3080;
inline constexpr std::uint16_t kAoRampDown = 0x3090;
inline constexpr std::uint16_t kAoRampControl = 0x30A0;
inline constexpr std::uint16_t kAoErrorDelay = 0x30B0;
inline constexpr std::uint16_t kAoMeasuredCurrent = 0x30C0;
inline constexpr std::uint16_t kStartInOperational = 0x5555;
inline constexpr std::uint16_t kDiReadState = 0x6000;
inline constexpr std::uint16_t kDiPolarity = 0x6002;
inline constexpr std::uint16_t kAiSensorType = 0x6110;
inline constexpr std::uint16_t kAiOperatingMode = 0x6112;
inline constexpr std::uint16_t kAiAutozero = 0x6125;
inline constexpr std::uint16_t kAiDecimalDigits = 0x6132;
inline constexpr std::uint16_t kAiFilterType = 0x61A0;
inline constexpr std::uint16_t kAiFilterConstant = 0x61A1;
inline constexpr std::uint16_t kDoWriteState = 0x6200;
inline constexpr std::uint16_t kDoPolarity = 0x6202;
inline constexpr std::uint16_t kDoFaultMode = 0x6206;
inline constexpr std::uint16_t kDoFaultState = 0x6207;
inline constexpr std::uint16_t kAoDecimalDigits = 0x6302;
inline constexpr std::uint16_t kAoOutputType = 0x6310;
inline constexpr std::uint16_t kAoFaultMode = 0x6340;
inline constexpr std::uint16_t kReceivedPvStatus = 0x6F52;
inline constexpr std::uint16_t kAiFieldValue = 0x7100;
inline constexpr std::uint16_t kAiScaling1Fv = 0x7120;
inline constexpr std::uint16_t kAiScaling1Pv = 0x7121;
inline constexpr std::uint16_t kAiScaling2Fv = 0x7122;
inline constexpr std::uint16_t kAiScaling2Pv = 0x7123;
inline constexpr std::uint16_t kAiOffset = 0x7124;
inline constexpr std::uint16_t kAiProcessValue = 0x7130;
inline constexpr std::uint16_t kAoProcessValue = 0x7300;
inline constexpr std::uint16_t kAoScaling1Pv = 0x7320;
inline constexpr std::uint16_t kAoScaling1Fv = 0x7321;
inline constexpr std::uint16_t kAoScaling2Pv = 0x7322;
inline constexpr std::uint16_t kAoScaling2Fv = 0x7323;
inline constexpr std::uint16_t kAoFieldValue = 0x7330;
inline constexpr std::uint16_t kAoFaultFieldValue = 0x7341;
inline constexpr std::uint16_t kReceivedPv = 0x7F50;

/// The AI profile points 2010h..2080h in order; each must lie between its neighbours (§3.3.1-8).
inline constexpr std::array<std::uint16_t, 8> kAiProfileChain = {
    kAiErrorMinimum,    kAiMinimum,           kAiBreakpointMinimum, kAiDeadbandMinimum,
    kAiDeadbandMaximum, kAiBreakpointMaximum, kAiMaximum,           kAiErrorMaximum};

/// 6110h sensor types (§3.3.13).
enum class SensorType : std::uint16_t {
  kVoltage5V = 40,     ///< 0-5000 mV
  kVoltage10V = 42,    ///< 0-10000 mV
  kCurrent4To20 = 51,  ///< 4000-20000 µA
  kCurrent0To20 = 52,  ///< 0-20000 µA
  kFrequency = 60,     ///< 0-10000 Hz over the 2090h window
  kPwm = 10000,        ///< duty cycle, 0-10000 = 0-100.00 %
};

/// 6112h operating modes (§3.3.14).
enum class OperatingMode : std::uint8_t { kDisabled = 0, kNormal = 1, kDigital = 10, kOnOff = 20 };

/// 6310h output types (§3.5.15).
enum class OutputType : std::uint16_t { kCurrent = 20, kDigital = 1000 };

/// 30A0h ramp control (§3.5.10).
enum class RampControl : std::uint8_t { kOff = 0, kAlways = 1, kUnlessCan = 2 };

/// 3001h/3010h control input 0: the CANopen message (6200h / 7330h, 7F50h).
inline constexpr std::uint8_t kControlCan = 0;

/// Full scale of the outputs (§3.5.3-5, 7341h): 0-2000 mA.
inline constexpr int kMaxOutputCurrent_mA = 2000;

// EMCY error codes (§4.1 "Supported EMCY Codes").
inline constexpr std::uint16_t kEmcyShortCircuit = 0x2320;
inline constexpr std::uint16_t kEmcyOpenCircuit = 0x3300;
inline constexpr std::uint16_t kEmcyHeartbeat = 0x8130;
inline constexpr std::uint16_t kEmcyInputLow = 0xFF00;
inline constexpr std::uint16_t kEmcyInputHigh = 0xFF01;
inline constexpr std::uint16_t kEmcyDigitalOutput = 0xFF02;

// Error descriptions (§4.1 "Supported Error Descriptions"): the high byte of the 1003h
// manufacturer field.
inline constexpr std::uint8_t kDescAnalogInput = 0x01;
inline constexpr std::uint8_t kDescDigitalOutput = 0x02;
inline constexpr std::uint8_t kDescProportionalOutput = 0x04;
inline constexpr std::uint8_t kDescHeartbeat = 0x08;

// 1029h sub-indexes (§3.1.9).
inline constexpr std::uint8_t kBehaviourCommunication = 1;
inline constexpr std::uint8_t kBehaviourDigitalInput = 2;
inline constexpr std::uint8_t kBehaviourAnalogInput = 3;
inline constexpr std::uint8_t kBehaviourDigitalOutput = 4;
inline constexpr std::uint8_t kBehaviourAnalogOutput = 5;

/// An error as the Quad records it (§3.1.4, §4.1): 1003h = (description << 24) | (channel << 16) |
/// EMCY code; 1001h uses bit 0 only (§3.1.3). The EMCY frame carries the same manufacturer field
/// in bytes 3-4 (channel, description), i.e. the 1003h entry's high half in CAN byte order.
/// @param channel 1-based channel (AINn/POUTn = n, FIN1/DOUT = 5, FIN2 = 6) or a node-ID.
canopen::ErrorEntry MakeErrorEntry(std::uint16_t code, std::uint8_t description, std::uint8_t channel);

}  // namespace canfleet::devices::quad
