#pragma once
/// @file The AX023241's programmable blocks on their objects, computed by the shared library
/// (blocks/): two math blocks (1.7, C3-1.4.50-1.4.61, Table 13), two lookup tables (1.6,
/// C3-1.4.37-1.4.45) and one PID (1.8, C3-1.3.32-1.3.37, C3-1.4.24-1.4.32, Table 14).
///
/// Math x (4000h.x enable, 4x00h-4x50h, 4021h/4023h/4032h -> 4030h.x): the encoder profile (five
/// inputs in a chain, operators 0-15 of Table 13, logic TRUE at >= 1, "/" by 0 = 100 %, results held
/// to 0..100 %); gain 4x40h / 100 (100 = 1.0, 1.7 "from -1.0 to 1.0").
/// Lookup table x (30x0h-30x8h): data response only (the X-Axis Type has no object, README-
/// dictionary 44, so the time response of 1.6.5 cannot be selected and 30x2h has no effect); 11
/// points X0..X10 (30x6h/30x7h sub 1-11), 30x5h sub N = response of the segment N-1..N (0 ramp to,
/// 1 jump to); the X source is read in the X axis' decimals (30x3h: a source value with d digits is
/// divided by 10^d and multiplied by 10^30x3h), so the manual's example of a math block (0 to
/// 100.00 %) driving a default table (0 to 100) works as printed (1.6.4).
/// PID (2453h-2457h, 2450h-2452h, 7450h-7456h, 6459h -> 2460h): G = 7450h/10, Ki = 2451h/10,
/// Kd = 2452h/10, tolerance 2450h/10 %, Ti/Td/cycle = 7452h/7454h/7456h x 10^-6459h s (6459h = 3:
/// ms); T = 0.001 s in the formula (1.8). Runs every cycle while it can change; sleeps otherwise.

#include <array>
#include <chrono>
#include <optional>
#include <vector>

#include "node/canopen/od/object_dictionary.hpp"
#include "node/devices/blocks/control_source.hpp"
#include "node/devices/blocks/lookup_table.hpp"
#include "node/devices/blocks/math_block.hpp"
#include "node/devices/blocks/pid.hpp"
#include "node/devices/encoder_dual_valve/encoder_objects.hpp"

namespace canfleet::devices::encoder {

class FunctionBlocks {
 public:
  using Ms = std::chrono::milliseconds;

  explicit FunctionBlocks(canopen::ObjectDictionary& od);

  void UpdateMath(const blocks::ControlSources& sources);
  void UpdateLookupTables(const blocks::ControlSources& sources);
  void UpdatePid(Ms elapsed, const blocks::ControlSources& sources);

  blocks::Signal Math(int n) const { return math_[static_cast<std::size_t>(n)].Output(); }
  blocks::Signal Lut(int n) const { return lut_[static_cast<std::size_t>(n)].Output(); }
  blocks::Signal Pid() const { return pid_.Output(); }

  /// The PID's next cycle while it can still change; nullopt when settled or disabled.
  std::optional<Ms> NextChange() const;
  void Reset();

  blocks::MathBlockParams MathParams(int block) const;
  blocks::LookupTableParams LutParams(int table) const;
  blocks::PidParams PidParameters() const;

 private:
  canopen::ObjectDictionary& od_;
  std::vector<blocks::MathBlock> math_;
  std::array<blocks::LookupTable, kLookupTables> lut_;
  blocks::Pid pid_;
  bool pid_active_ = false;
  bool pid_inputs_pending_ = false;
  blocks::Signal seen_target_ = blocks::Signal::NotAvailable();
  blocks::Signal seen_feedback_ = blocks::Signal::NotAvailable();
};

}  // namespace canfleet::devices::encoder
