#pragma once
/// @file The valve's (source, number) wiring (UMAX020411A §1.5 Tables 15-17): what every block
/// input reads, with the limits and digits its consumer normalises with.
///
/// | source | number | value | limits (Table 17) | digits |
/// |---|---|---|---|---|
/// | 1 CANopen message | 1-8 | 7300h.n, or bit n-1 of 6200h.1 when OUTn is a digital type (6310h 1000/1020) |
/// 7320h.n / 7322h.n | 6302h.n | | | 9-12 | bit n-9 of 6200h.2 (DO1-DO4) | 7320h.n / 7322h.n | 6302h.n | | |
/// 13-24 | 2500h.(n-12) | 2520h / 2522h | 2502h | | 2 analog input | 1-12 | 7100h.n, or 6020h.n in digital
/// mode (InputBlock::AsSource) | 7120h / 7122h | 2102h | | 3 constant | 1-15 | 5010h.n (REAL32) | none | - |
/// | 4 PID | 1-4 | 2460h.n | 0 / 1000 | 1 |
/// | 5 lookup table | 1-12 | 3yz8h | Y range (§1.7.2) | 3yz4h |
/// | 6 math | 1-6 | 4030h.n | 4021h / 4023h | 4032h |
/// | 7 logic | 1-4 | 3320h.n | 0 / 1000 | 1 |
/// | 8 output commanded FV | 1-12 | 7330h.n (digital types: the logic state) | 7320h / 7322h | 6302h |
/// | 9 output feedback FV | 1-12 | 2370h.n | 7320h / 7322h | 6302h |
/// | 10 power supply | - | 5020h in 0.1 V | none | 1 |
/// | 11 processor temperature | - | 5030h in 0.1 degC | none | 1 |
///
/// Table 17's "Dec Digits" column names 6132h (PV digits) for the analog input while the value is
/// the FV: the FV's own 2102h is used. Table 17 gives the 6302h/7320h/7322h PV scaling for the
/// output FVs (sources 8, 9): kept as printed.
///
/// Errors: an analog input in span fault (after its delay) and, for CANopen messages, an RPDO whose
/// event timer expired: while RPDO n is timed out, every object its mapping (1600h + n - 1) named
/// when the timeout struck reads as faulted, so outputs driven by it take their fault reaction
/// (6340h/7341h, 6250h/6260h) — "no fault is detected for any of the control signals" (§1.4).

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "node/canopen/od/object_dictionary.hpp"
#include "node/devices/blocks/control_source.hpp"
#include "node/devices/od_ref.hpp"
#include "node/devices/valve_12in12out/valve_objects.hpp"

namespace canfleet::devices::valve {

class InputBlock;
class ProgramBlocks;

class ValveSources {
 public:
  explicit ValveSources(canopen::ObjectDictionary& od);
  ValveSources(const ValveSources&) = delete;
  ValveSources& operator=(const ValveSources&) = delete;

  /// The blocks whose outputs are sources (set once, at attach).
  void Connect(const InputBlock* inputs, const ProgramBlocks* program) {
    inputs_ = inputs;
    program_ = program;
  }

  const blocks::ControlSources& sources() const { return sources_; }
  blocks::Signal Resolve(blocks::SourceRef ref) const { return sources_.Resolve(ref); }

  /// RPDO `rpdo` (1-based) timed out (true) or is received again (false).
  void SetRpdoTimeout(std::size_t rpdo, bool active);
  /// Reset application: no RPDO is timed out any more (the stack forgot its errors).
  void ClearRpdoTimeouts() { timed_out_.clear(); }

 private:
  blocks::Signal Resolve(blocks::SourceKind kind, std::uint8_t number) const;
  blocks::Signal CanMessage(std::uint8_t number) const;
  blocks::Signal OutputValue(const OdRef& value, int ch) const;
  bool TimedOut(std::uint16_t index, std::uint8_t sub) const;

  canopen::ObjectDictionary& od_;
  blocks::ControlSources sources_;
  const InputBlock* inputs_ = nullptr;
  const ProgramBlocks* program_ = nullptr;
  std::array<OdRef, kOutputs> pv_, scaling1_, scaling2_, pv_digits_, type_, commanded_, feedback_;
  std::array<OdRef, 2> write_state_;
  std::array<OdRef, 12> extra_, extra_scaling1_, extra_scaling2_, extra_digits_;
  std::array<OdRef, 15> constants_;
  OdRef supply_, temperature_;
  /// Per timed-out RPDO, the (index, sub) its mapping named.
  std::vector<std::pair<std::size_t, std::vector<std::pair<std::uint16_t, std::uint8_t>>>> timed_out_;
};

/// A signal read as ON/OFF (enable and override inputs, §1.5; digital outputs, §1.4): without
/// limits (constants, supply) ON = not zero; with limits ON = at or past the middle of them (a 0/1
/// signal is ON at 1, an analog input at half its 7120h..7122h span). Not available = OFF.
bool IsOn(const blocks::Signal& s);

}  // namespace canfleet::devices::valve
