#pragma once
/// @file Loading a topology file (topologies/README.md): protobuf text format against
/// canfleet_topology.proto, then validation and defaults, so that the fleet manager gets a
/// complete, consistent description and never has to guess.
///
/// Every refusal is one TopologyError whose message is "FILE:LINE:COL: FIELD: reason", e.g.
///   demo.textproto:12:5: node[2].node_id: quad-6 has node-ID 5 on bus can0, already used by
///   node quad-5 (line 8)
/// FIELD is the path of the offending field (indices count from 0); LINE and COL are 1-based and
/// point at the field in the file (or, for a missing field, at the message that lacks it).
/// A syntax error reads "FILE:LINE:COL: syntax error: <what the parser says>"; a file that cannot
/// be read reads "FILE: <why>".
///
/// After loading, `spec` holds every default (see ApplyDefaults in the .cpp and the README):
///   bus.bitrate 500000; orchestrator.control tcp://127.0.0.1:29700; orchestrator.listen
///   [tcp://127.0.0.1:29600]; orchestrator.start_nodes true; orchestrator.state_root
///   <topology dir>/.canfleet/<name>; node.state_dir <state_root>/<node name>; node.node_id one
///   per bus; node.restart.backoff_ms 500; node.log_level "info"; heartbeat consumers given by
///   node name get that node's node-ID on the first bus both share.
/// Every path in `spec` (state_root, state_dir, eds, dcf) is absolute and lexically normal.
///
/// A topology that loads may still not work as written: `warnings` says where and why (a
/// heartbeat consumed from a node that sends none, an RPDO deadline nothing feeds, a bus its
/// periodic traffic overfills; topologies/README.md "What loading warns about"), and `loads` gives
/// each bus's offered periodic load.

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "orchestrator/topology/canfleet_topology.pb.h"
#include "orchestrator/topology/topology_warning.hpp"

namespace canfleet::topology {

/// A topology file that was refused.
class TopologyError : public std::runtime_error {
 public:
  /// @param line, column 1-based; 0 when the error is about the file as a whole
  /// @param field the field's path ("node[2].node_id"); empty for syntax and file errors
  TopologyError(std::string file, int line, int column, std::string field, std::string reason);

  const std::string& file() const { return file_; }
  int line() const { return line_; }
  int column() const { return column_; }
  const std::string& field() const { return field_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string file_;
  int line_;
  int column_;
  std::string field_;
  std::string reason_;
};

/// A topology that loaded: the specification with every default applied, and the file's
/// absolute path.
struct LoadedTopology {
  Topology spec;
  std::filesystem::path file;
  std::vector<int> step_lines;  ///< the line of each scenario step (1-based), for reports
  /// What the file may want to change though it loads: old names (e.g. a deprecated signal
  /// name, noted while checking), then configurations that cannot work (topology_warnings.hpp),
  /// in a stable order.
  std::vector<TopologyWarning> warnings;
  /// The periodic load each bus is offered (bus_load.hpp), one per bus in file order.
  std::vector<BusLoad> loads;
};

/// Reads, parses, validates and completes a topology file. Relative paths inside it are relative
/// to the file's folder; messages name the file as given here.
/// @throws TopologyError
LoadedTopology LoadTopology(const std::filesystem::path& file);

/// The same for text already in memory (tests, fuzzing). `file_for_messages_and_relative_paths`
/// names the file in messages, and its folder anchors relative paths; it need not exist.
/// Any text gives a LoadedTopology or a TopologyError, never a crash.
/// @throws TopologyError
LoadedTopology ParseTopology(std::string_view text,
                             const std::filesystem::path& file_for_messages_and_relative_paths);

}  // namespace canfleet::topology
