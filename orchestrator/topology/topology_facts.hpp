#pragma once
/// @file What the topology loader learns while it checks a file, shared by its checks (node
/// checks, scenario checks) and its defaults, and the small text rules of its messages. Internal
/// to the loader.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "node/canopen/od/object_dictionary.hpp"
#include "node/devices/registry.hpp"
#include "orchestrator/topology/canfleet_topology.pb.h"
#include "orchestrator/topology/located_error.hpp"

namespace canfleet::topology::detail {

namespace fs = std::filesystem;

inline constexpr std::uint32_t kUnconfiguredNodeId = 255;  // an LSS slave without a node-ID

/// `text` quoted for a message, control characters escaped.
std::string Quote(std::string_view text);
/// "1400h", as CiA documents write object indices.
std::string Hex(std::uint32_t value);
/// "1 CAN port", "2 CAN ports".
std::string PortsText(std::size_t ports);
/// A name that can be a folder, a command-line word and a control-API key: printable ASCII
/// without spaces, slashes or backslashes, not "." or "..". Returns what is wrong, or "".
std::string NameProblem(std::string_view name);
/// Bus names also appear in "--bus can0@tcp://..." and socketcand's "< open can0 >": letters,
/// digits, '_', '-', '.'. Returns what is wrong, or "".
std::string BusNameProblem(std::string_view name);
/// "IN1.voltage_mV": CHANNEL.quantity, both identifiers.
bool LooksLikeSignalName(std::string_view name);

/// What validation learned about one node, for cross-checks and for the defaults.
struct NodeFacts {
  int index = 0;
  std::string name;
  Loc loc;
  std::size_t ports = 1;
  std::string kind;                              // "quad-controller", or "generic node" for an EDS-only one
  std::vector<std::uint32_t> ids;                // one per port (expanded)
  std::vector<Loc> id_locs;                      // where each port's node-ID is written
  std::vector<std::string> buses;                // one per port
  fs::path state_dir;                            // resolved
  fs::path eds;                                  // resolved, or empty
  fs::path dcf;                                  // resolved, or empty
  const devices::DeviceInfo* variant = nullptr;  // the catalog entry, or null for a generic node
  devices::SimulatedIo* io = nullptr;  // the variant's signals (NodeChecks::signals_): io checks set them
  std::shared_ptr<const std::vector<canopen::ObjectDictionary>> dictionaries;  // one per port
  std::uint32_t producer_ms = 0;

  // The node-ID on `bus`, or nullopt when the node is not on it.
  std::optional<std::uint32_t> IdOn(std::string_view bus) const {
    for (std::size_t p = 0; p < buses.size(); ++p) {
      if (buses[p] == bus) return ids[p];
    }
    return std::nullopt;
  }
};

struct BusFacts {
  int index = 0;
  Loc loc;
};

/// Everything the checks have learned so far, in the order they run: buses, then nodes, then
/// heartbeats and the scenario, which refer to both.
struct TopologyFacts {
  const Topology& spec;
  fs::path dir{};         ///< the file's folder: relative paths start there
  fs::path state_root{};  ///< resolved
  std::map<std::string, BusFacts> buses{};
  std::vector<NodeFacts> nodes{};
  std::map<std::pair<int, int>, std::uint32_t> consumer_ids{};  ///< (node index, consumer index) -> node-ID

  /// `path` relative to the file's folder, made absolute and lexically normal.
  fs::path Resolve(const std::string& path) const;
  const NodeFacts* FindNode(std::string_view name) const;
  /// "can0, can1", for messages.
  std::string BusNames() const;
  /// The node called `name` of the topology; refuses `field` of `s` otherwise.
  const NodeFacts& RequireNode(const Scope& s, std::string_view field, const std::string& name) const;
  /// Refuses the index-th `field` of `s` when `node` is not on `bus`.
  void CheckOnBus(const Scope& s, std::string_view field, int index, const NodeFacts& node,
                  const std::string& bus) const;
};

}  // namespace canfleet::topology::detail
