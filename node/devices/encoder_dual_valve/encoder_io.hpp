#pragma once
/// @file The simulated I/O of the AX023241 encoder dual valve controller (design decision 5): what a
/// test (or `canfleet io`) puts on its pins and what it measures on its outputs. Names follow
/// node/devices/README.md "Signals" (IN1/IN2, OUT1/OUT2: the manual's Input 1/2, Output 1/2). Every input
/// starts in its normal range: an idle node at factory defaults raises no fault.
///
/// Inputs
///   ENC.drive             rpm|counts|channels  which inputs turn the shaft (default rpm):
///                          rpm      ENC.speed_rpm with ENC.pulses_per_rev,
///                          counts   ENC.speed_counts_s (quadrature edges per second),
///                          channels IN1.frequency_Hz / IN2.frequency_Hz as the raw A/B channels
///   ENC.speed_rpm         0..60000, 0        shaft speed
///   ENC.speed_counts_s    0..2000000, 0      shaft speed in edges/s (4 per encoder pulse)
///   ENC.direction         forward|reverse    forward = QA leads QB (the counter counts up)
///   ENC.pulses_per_rev    1..100000, 4       the encoder's pulses per revolution (per channel);
///                                            the default matches 3413h's default
///   ENC.position_counts   +-1e15, 0          setting it moves the shaft to this position (edges
///                                            from power-on); the decoder counts every edge passed
///   INn.level             open|high|low      the pin as a digital input; open = floating, 2020h's
///                                            pull decides
///   INn.frequency_Hz      0..50000, 25       signal frequency (frequency/PWM inputs, A/B channels)
///   INn.duty_pct          0..100, 50         PWM duty cycle
///   OUTn.load             nominal|open|short the load on OUTn
///   OUTn.resistance_ohm   0.5..1000, 8       coil resistance (24 V / 8 ohm = 3 A > the 2.5 A range)
///   VPS.voltage_mV        0..70000, 24000    supply voltage (9..60 V operating, §4.1; 5020h in V)
///   TEMP.temperature_C    -55..150, 25       processor temperature (5030h)
/// Outputs
///   ENC.shaft_counts      the shaft position in edges since power-on
///   OUTn.current_mA       current through the load (= 2370h)
///   OUTn.voltage_mV       mean voltage across the load
///   OUTn.duty_pct         duty cycle of the high-side driver
///   OUTn.frequency_Hz     driver frequency (25 kHz for current/voltage, 2380h for PWM, 0 for DC)
///   OUTn.on               the driver is on
///   OUTn.hotshot          a hotshot output is in its hotshot phase (Figure 5)
///   OUTn.tripped          the short-circuit protection has the driver off (1.5, retrying)

#include <array>
#include <vector>

#include "node/devices/encoder_dual_valve/encoder_objects.hpp"
#include "node/devices/simulated_io.hpp"

namespace canfleet::devices::encoder {

inline constexpr const char* kDriveRpm = "rpm";
inline constexpr const char* kDriveCounts = "counts";
inline constexpr const char* kDriveChannels = "channels";
inline constexpr const char* kForward = "forward";
inline constexpr const char* kReverse = "reverse";
inline constexpr const char* kLevelOpen = "open";
inline constexpr const char* kLevelHigh = "high";
inline constexpr const char* kLevelLow = "low";
inline constexpr const char* kLoadNominal = "nominal";
inline constexpr const char* kLoadOpen = "open";
inline constexpr const char* kLoadShort = "short";

struct EncoderIo {
  /// Declares every signal on `io`.
  explicit EncoderIo(SimulatedIo& io);

  SimulatedIo& io;
  IoSignal* drive = nullptr;
  IoSignal* speed_rpm = nullptr;
  IoSignal* speed_counts = nullptr;
  IoSignal* direction = nullptr;
  IoSignal* pulses_per_rev = nullptr;
  IoSignal* position = nullptr;
  std::array<IoSignal*, kInputs> level{};
  std::array<IoSignal*, kInputs> frequency{};
  std::array<IoSignal*, kInputs> duty{};
  std::array<IoSignal*, kOutputs> load{};
  std::array<IoSignal*, kOutputs> resistance{};
  IoSignal* supply = nullptr;
  IoSignal* temperature = nullptr;

  IoSignal* shaft_counts = nullptr;
  std::array<IoSignal*, kOutputs> current{};
  std::array<IoSignal*, kOutputs> voltage{};
  std::array<IoSignal*, kOutputs> out_duty{};
  std::array<IoSignal*, kOutputs> out_frequency{};
  std::array<IoSignal*, kOutputs> on{};
  std::array<IoSignal*, kOutputs> hotshot{};
  std::array<IoSignal*, kOutputs> tripped{};
};

/// The old names of the encoder controller's signals (VPS.voltage_V, OUTn.voltage_V) and their new
/// ones; the one table, registered by EncoderIo.
std::vector<IoAlias> EncoderSignalAliases();

/// The catalog's signal declaration (registry.hpp `declare_signals`).
void DeclareEncoderSignals(SimulatedIo& io);

}  // namespace canfleet::devices::encoder
