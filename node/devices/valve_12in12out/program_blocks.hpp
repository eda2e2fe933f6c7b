#pragma once
/// @file The valve's programmable blocks on their objects (UMAX020411A §1.6-1.9): 6 math blocks
/// (4000h-4650h, Table 30), 12 lookup tables (3010h-3128h), 4 logic blocks (3300h-3733h) and 4 PID
/// loops (2450h-2460h, 6459h, 7450h-7456h). The algorithms are the shared family library
/// (node/devices/blocks/); this file reads their parameters from the objects each run, feeds them
/// through ValveSources and writes the outputs 4030h, 3yz8h, 3310h/3320h and 2460h.
///
/// Order in one run (the family's, blocks/signal.hpp): math -> lookup tables -> logic -> PID; a
/// block reading its own output or a later block sees the previous run (no loop is evaluated twice).
/// When an output changed, the controller runs once more one millisecond later, so a value read
/// "one run late" still arrives and a loop settles without a fixed tick.
///
/// Units: PID gains 7450h/2451h/2452h and tolerance 2450h have 1 decimal (§1.6); 7452h/7454h/7456h
/// are seconds with 6459h decimals (default 3: milliseconds); the cycle is rounded to whole
/// milliseconds, at least 1. Math gains 4y40h have 2 decimals; input scaling 4y20h/4y22h has 4y03h
/// decimals; outputs 4021h/4023h have 4032h decimals (§1.9).

#include <array>
#include <chrono>
#include <optional>

#include "node/canopen/od/object_dictionary.hpp"
#include "node/devices/blocks/logic_block.hpp"
#include "node/devices/blocks/lookup_table.hpp"
#include "node/devices/blocks/math_block.hpp"
#include "node/devices/blocks/pid.hpp"
#include "node/devices/od_ref.hpp"
#include "node/devices/valve_12in12out/valve_objects.hpp"
#include "node/devices/valve_12in12out/valve_sources.hpp"

namespace canfleet::devices::valve {

class ProgramBlocks {
 public:
  ProgramBlocks(canopen::ObjectDictionary& od, const ValveSources& sources);
  ProgramBlocks(const ProgramBlocks&) = delete;
  ProgramBlocks& operator=(const ProgramBlocks&) = delete;

  /// One run after `elapsed` (> 0). Returns true if any block output changed.
  bool Run(std::chrono::milliseconds elapsed);
  /// Time until a block needs the next run (a PID cycle, a time-response table).
  std::optional<std::chrono::milliseconds> NextWake() const;
  /// Reset application: tables stopped, PID state cleared.
  void Reset();

  blocks::Signal PidOutput(int n) const { return pids_[n].pid.Output(); }
  blocks::Signal LutOutput(int n) const { return luts_[n].table.Output(); }
  blocks::Signal MathOutput(int n) const { return maths_[n].block.Output(); }
  blocks::Signal LogicOutput(int n) const { return logics_[n].block.Output(); }

 private:
  struct Lut {
    Lut() : table(blocks::ValveLookupTableProfile()) {}
    blocks::LookupTable table;
    blocks::LookupTableParams params;  ///< reused every run (no allocation once sized)
    OdRef source, number, repeat, y_digits, output;
    std::array<OdRef, kLutPoints> response, x, y;
  };
  struct Pid {
    Pid() : pid(blocks::ValvePidProfile()) {}
    blocks::Pid pid;
    OdRef tolerance, ki, kd, target_source, target_number, feedback_source, feedback_number, response, digits,
        gain, ti, td, cycle, output;
    blocks::PidParams params;  ///< as of the last run
    blocks::Signal target, feedback;
    bool has_last = false;
    /// Inputs or parameters changed and no cycle has seen them yet.
    bool dirty = false;
  };
  struct Math {
    Math() : block(blocks::ValveMathProfile(), 0) {}
    blocks::MathBlock block;
    blocks::MathBlockParams params;  ///< reused every run
    OdRef enable, out_scaling1, out_scaling2, out_digits, output;
    std::array<OdRef, 6> source, number, function, digits, scaling1, scaling2, gain;
    std::array<OdRef, 3> op;
  };
  struct Logic {
    blocks::LogicBlock block;
    OdRef enable, selected, output;
    std::array<OdRef, 3> table, op;
    std::array<std::array<std::array<OdRef, 5>, 3>, 3> conditions;  ///< [function][condition][sub 1..5]
  };

  void RunMath(Math& m);
  void RunLut(Lut& l, std::chrono::milliseconds elapsed);
  void RunLogic(Logic& l);
  void RunPid(Pid& p, std::chrono::milliseconds elapsed);
  blocks::PidParams ReadPidParams(const Pid& p) const;

  const ValveSources& sources_;
  std::array<Lut, kLookupTables> luts_;
  std::array<Pid, kPids> pids_;
  std::array<Math, kMathBlocks> maths_;
  std::array<Logic, kLogicBlocks> logics_;
};

}  // namespace canfleet::devices::valve
