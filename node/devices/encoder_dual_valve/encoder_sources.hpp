#pragma once
/// @file The AX023241's (source, number) wiring (1.3, Tables 6 and 7) on the shared block library
/// (blocks/control_source.hpp): the product's source table and the resolver that turns a pair into
/// the producing block's value and limits.
///
/// | source (Table 6)                   | number | value, limits (digits)                          |
/// |---|---|---|
/// | 1 received CAN message             | 1-2    | 7300h.n, 7320h.n..7322h.n (6302h.n): the AO PVs RPDO1 maps
/// | |                                    | 3-8    | 2500h.n-2, 2520h..2522h (2502h): the extra received PVs
/// | | 2 quadrature encoder input measured| 1-2    | 7100h.n, 7120h.n..7122h.n (pulse_inputs.hpp)    | | 3
/// output target value              | 1-2    | 7330h.n, 7321h.n..7323h.n (6332h.n)             | | 4 output
/// current feedback          | 1-2    | 2370h.n, 0..2500 mA                             | | 5 lookup table |
/// 1-2    | 30x8h, lowest..highest Y used (30x4h)           | | 6 math function block              | 1-2    |
/// 4030h.n, 4021h.n..4023h.n (4032h.n)             | | 8 PID                              | 1      | 2460h,
/// 0..1000 (1 digit)                        | | 9 control constant                 | 1-12   | 5010h.n (a
/// float without limits: read as %)     | | 12 power supply measured           | 1      | 5020h V, 0..60 V |
/// | 13 processor temperature measured  | 1      | 5030h degC, -40..125 degC                       |
/// | 7 logic, 10 set/reset, 11 DTC      | Table 7| not available: the manual gives them no objects |
///
/// Table 7's ranges are kept except three (README.md, "Control sources"): received CAN message
/// [1...5] -> 1-8 (two AO PVs plus six extra received PVs; the defaults wire output n to message n
/// = 7300h.n, which RPDO1 writes), lookup table [1...3] -> 1-2 (two tables exist), control
/// constant [1...10] -> 1-12 (5010h has 12 sub-indexes, sub 1 FALSE and sub 2 TRUE included).
/// A received value is in error while an RPDO that maps it has timed out (1400h-1403h sub 5):
/// the outputs it drives then take their control fault response (1.4 Table 12).

#include <array>
#include <bitset>
#include <cstdint>
#include <span>

#include "node/canopen/od/object_dictionary.hpp"
#include "node/devices/blocks/control_source.hpp"
#include "node/devices/encoder_dual_valve/encoder_objects.hpp"

namespace canfleet::devices::encoder {

class PulseInputs;
class ValveOutputs;
class FunctionBlocks;

/// Table 6 with the number ranges used here.
std::span<const blocks::SourceType> EncoderValveSourceTypes();

class EncoderSources {
 public:
  explicit EncoderSources(canopen::ObjectDictionary& od);
  EncoderSources(const EncoderSources&) = delete;
  EncoderSources& operator=(const EncoderSources&) = delete;

  void SetProviders(const PulseInputs* inputs, const ValveOutputs* outputs, const FunctionBlocks* blocks);
  const blocks::ControlSources& sources() const { return sources_; }

  /// RPDO `number` (1-based) timed out (true) or received again (false).
  void SetRpdoTimeout(std::uint8_t number, bool active);
  bool AnyRpdoTimeout() const { return rpdo_timeout_.any(); }

  /// Whether any block input (output control/enable/override, lookup X, enabled math inputs, PID)
  /// is wired to block `number` of `kind` now.
  bool Wired(blocks::SourceKind kind, std::uint8_t number) const;

 private:
  blocks::Signal Resolve(blocks::SourceKind kind, std::uint8_t number) const;
  blocks::Signal Received(std::uint8_t number) const;
  bool TimedOut(std::uint16_t index, std::uint8_t sub) const;
  bool PairIs(std::uint16_t source_index, std::uint8_t source_sub, std::uint16_t number_index,
              std::uint8_t number_sub, blocks::SourceKind kind, std::uint8_t number) const;

  canopen::ObjectDictionary& od_;
  const PulseInputs* inputs_ = nullptr;
  const ValveOutputs* outputs_ = nullptr;
  const FunctionBlocks* blocks_ = nullptr;
  std::bitset<4> rpdo_timeout_;
  blocks::ControlSources sources_;
};

}  // namespace canfleet::devices::encoder
