#pragma once
/// @file The data logger's programmable blocks, wired by (source, number) pairs (UMAX181001 §1.4
/// Tables 13-15, §1.5-§1.7, §3.4.31-3.4.66), on the family library (node/devices/blocks/):
/// - twelve lookup tables LT01-LT12 (3yz0h-3yz8h), data or time response;
/// - four logic blocks LB1-LB4 (3300h-3320h, 3x01h-3x33h), each selecting one of three tables;
/// - six math blocks (4000h-4032h, 4y00h-4y50h) with Table 23's operators 0-17 in pairs.
/// One Update is one application cycle: math -> lookup tables -> logic (signal.hpp's family order;
/// a block reading a later one sees its previous cycle's output, and the device runs another
/// cycle while outputs still move).
///
/// Source values (Table 13, value column damaged: list order, README C43) and the limits a
/// consumer normalises them with (Table 15):
///   1 RPDO 1-12       2500h.n, 2520h.n .. 2522h.n, 2502h.n decimals
///   2 analog input    7100h.n (6020h.n in modes 10/20), 7120h.n .. 7122h.n (analog_block.hpp)
///   3 TC CJ 1-4       2162h.n uV, E(-40 C) .. E(210 C)       4 TC 1-4  6100h.n, 2170h .. 2171h
///   5 constant 1-15   5010h.n (float, no limits)             6 LUT 1-12  3yz8h, Y range
///   7 math 1-6        4030h.n, 4021h .. 4023h, 4032h         8 logic 1-4 3320h (0..100.0 %)
///   9 supply          5020h in 0.1 V, no limits ("1 (fixed)")
///  10 CPU temperature 5030h in 0.1 C, no limits
///
/// Rules the SDO validators add (§1.5.1, §3.4.29-3.4.37, Table 14):
/// - a number object (3yz1h, 4y01h, condition subs 2 and 4) must lie in its source's range (Table
///   14) when the source is numbered; a source may be written first (the pair is then "not
///   available" until the number fits).                                               06090031h/32h
/// - 3yz6h, data response: X1 <= X2 <= ... over the used points (kValueTooLow below the point
///   before, kValueTooHigh above the point after) and inside the source's Scaling 1..2 when it has
///   a range; time response: points 2-11 from 1 to 86 400 000 ms.
/// - 2520h < 2522h (§3.4.29-30).
/// Selecting the time response (3yz5h sub 1 = 1) sets 3yz3h = 0 and point 1 to (0, 0) (§1.5.4).

#include <array>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "node/canopen/od/object_dictionary.hpp"
#include "node/devices/blocks/control_source.hpp"
#include "node/devices/blocks/logic_block.hpp"
#include "node/devices/blocks/lookup_table.hpp"
#include "node/devices/blocks/math_block.hpp"
#include "node/devices/datalogger_tc_analog/datalogger_objects.hpp"
#include "node/devices/od_ref.hpp"

namespace canfleet::devices::datalogger {

class ProgramBlocks {
 public:
  /// @param inputs resolves the sources that are not programmable blocks (RPDO values, inputs,
  ///        thermocouples, constants, supply, temperature).
  ProgramBlocks(canopen::ObjectDictionary& od, blocks::SignalResolver inputs);

  /// One cycle; `elapsed` since the previous one drives the time responses. True if any output
  /// object (3yz8h, 3310h, 3320h, 4030h) changed.
  bool Update(std::chrono::milliseconds elapsed);
  /// How long until a running time response changes its output (0 = it is ramping: next cycle);
  /// nullopt when no table will change by itself.
  std::optional<std::chrono::milliseconds> NextChange() const;

  const blocks::ControlSources& sources() const { return sources_; }
  const blocks::LookupTable& Table(int t) const { return tables_.at(static_cast<std::size_t>(t - 1)).block; }

  /// Reset application: tables stopped, outputs as at power-on.
  void Reset();

  /// Installs the validators and the time-response listener described above.
  void InstallHooks(canopen::ObjectDictionary& od);

 private:
  struct TableSlot {
    OdRef source, number, auto_repeat, y_digits, x_type;
    std::array<OdRef, kLutPoints> x, y, response;  // response[0] unused (sub 1 = X type)
    OdRef output;
    blocks::LookupTable block{blocks::DataLoggerLookupTableProfile()};
    blocks::LookupTableParams params;
  };
  struct MathInput {
    OdRef source, number, function, digits, scaling1, scaling2, gain;
  };
  struct MathSlot {
    OdRef enable, scaling1, scaling2, digits, output;
    std::array<MathInput, kMathInputs> inputs;
    std::array<OdRef, kMathFunctions> operators;
    std::unique_ptr<blocks::MathBlock> block;
    blocks::MathBlockParams params;
  };
  struct Condition {
    OdRef arg1_source, arg1_number, arg2_source, arg2_number, op;
  };
  struct LogicSlot {
    OdRef enable, selected, output;
    std::array<OdRef, 3> tables, operators;
    std::array<std::array<Condition, 3>, 3> conditions;
    blocks::LogicBlock block;
    blocks::LogicBlockParams params;
  };

  blocks::Signal Resolve(blocks::SourceKind kind, std::uint8_t number) const;
  void ReadTable(TableSlot& t);
  void ReadMath(MathSlot& m);
  void ReadLogic(LogicSlot& l);

  blocks::SignalResolver inputs_;
  blocks::ControlSources sources_;
  blocks::MathProfile math_profile_;
  std::array<TableSlot, kLookupTables> tables_;
  std::array<MathSlot, kMathBlocks> maths_;
  std::array<LogicSlot, kLogicBlocks> logics_;
};

}  // namespace canfleet::devices::datalogger
