#pragma once
/// @file What loading a topology reports besides refusals: warnings about configurations that
/// load but cannot work (a heartbeat nobody sends, an RPDO deadline nobody feeds, a bus its
/// periodic traffic overfills; topologies/README.md "What loading warns about"), and the offered
/// load of each bus. `canfleet check` prints them, `canfleet up` and `canfleet test` log them.

#include <cstdint>
#include <string>

namespace canfleet::topology {

/// A configuration that loads but cannot work as written. Located like a TopologyError.
struct TopologyWarning {
  std::string file;
  int line = 0;  ///< 1-based
  int column = 0;
  std::string field;  ///< "node[1].heartbeat.consumer[0]"
  std::string reason;

  /// "FILE:LINE:COL: warning: FIELD: reason", one line.
  std::string Message() const;
};

/// The periodic traffic a bus is offered once the fleet runs as the topology configures it, as
/// fractions of its bit rate (1.0 = 100 %), with frame lengths from bus/physics/frame_timing.hpp.
struct BusLoad {
  std::string bus;
  std::uint32_t bitrate = 0;
  bool unpaced = false;  ///< no timing model: the bus carries anything (no warning)
  double tpdos = 0;
  double heartbeats = 0;
  double sync = 0;

  double Total() const { return tpdos + heartbeats + sync; }
  /// "231 % of 250 kbit/s (TPDOs 226 %, heartbeats 5 %)"; parts that offer nothing are left out.
  std::string Describe() const;
};

/// A share of a bus as text: "231 %", "4.8 %", "0 %" (one decimal below 10 %).
std::string PercentText(double fraction);

}  // namespace canfleet::topology
