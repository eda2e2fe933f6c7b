// Fuzzes the topology loader (orchestrator/topology/topology_loader.hpp) with arbitrary text: any
// input gives a LoadedTopology or a TopologyError, nothing else (another exception escaping is a
// crash here). What loads must be complete, as the fleet manager relies on: every default
// applied, node-IDs one per bus and unique per bus, paths absolute. A refusal must name the file
// and, when it has a line, a 1-based line and column.
//
// The file is placed in the source tree's topologies/ so the seeds' relative EDS paths resolve.
// Inputs naming /proc, /sys or /dev are skipped: reading a special file (/proc/kmsg) could block,
// and the loader trusts the file system like any program given a path.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "orchestrator/topology/topology_loader.hpp"

using namespace canfleet::topology;

namespace {

const std::filesystem::path kFile =
    std::filesystem::path(CANFLEET_SOURCE_DIR) / "topologies" / "fuzz.textproto";

[[noreturn]] void Abort(const char* what, const std::string& detail, std::string_view input) {
  std::fprintf(stderr, "topology fuzz: %s: %s\n--- input ---\n%.*s\n", what, detail.c_str(),
               static_cast<int>(input.size()), input.data());
  std::abort();
}

void CheckLoaded(const LoadedTopology& t, std::string_view input) {
  const Topology& s = t.spec;
  if (s.name().empty()) Abort("loaded without a name", "", input);
  if (s.bus_size() == 0) Abort("loaded without a bus", "", input);
  if (s.orchestrator().control().empty() || s.orchestrator().listen_size() == 0 ||
      !s.orchestrator().has_start_nodes())
    Abort("orchestrator defaults missing", s.orchestrator().ShortDebugString(), input);
  if (!std::filesystem::path(s.orchestrator().state_root()).is_absolute())
    Abort("state_root not absolute", s.orchestrator().state_root(), input);
  for (const Bus& bus : s.bus()) {
    if (bus.bitrate() < 10000 || bus.bitrate() > 1000000)
      Abort("bitrate out of range", bus.ShortDebugString(), input);
  }
  std::set<std::pair<std::string, std::uint32_t>> ids;
  for (const Node& node : s.node()) {
    if (node.node_id_size() != node.bus_size())
      Abort("node_id not one per bus", node.ShortDebugString(), input);
    for (int p = 0; p < node.bus_size(); ++p) {
      if (node.node_id(p) != 255 && !ids.emplace(node.bus(p), node.node_id(p)).second)
        Abort("duplicate node-ID loaded", node.ShortDebugString(), input);
    }
    if (!std::filesystem::path(node.state_dir()).is_absolute())
      Abort("state_dir not absolute", node.state_dir(), input);
    if (!node.eds().empty() && !std::filesystem::path(node.eds()).is_absolute())
      Abort("eds not absolute", node.eds(), input);
    if (node.restart().backoff_ms() == 0 || node.log_level().empty())
      Abort("node defaults missing", node.ShortDebugString(), input);
    for (const HeartbeatConsumer& c : node.heartbeat().consumer()) {
      if (c.node_id() < 1 || c.node_id() > 127)
        Abort("consumer without a node-ID", c.ShortDebugString(), input);
    }
  }
}

}  // namespace

// Entropic scheduling (libFuzzer's default) updates a frequency for every coverage feature of
// every run; one run here executes so much node code (a device's simulated I/O, EDS parsing,
// SDO value encoding) that this bookkeeping made it ~25x slower: 28 instead of 750 runs/s. It is
// off unless the command line sets -entropic itself.
extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  static std::vector<char*> args;
  static char no_entropic[] = "-entropic=0";
  for (int i = 1; i < *argc; ++i) {
    if (std::string_view((*argv)[i]).rfind("-entropic=", 0) == 0) return 0;
  }
  args.assign(*argv, *argv + *argc);
  args.push_back(no_entropic);
  args.push_back(nullptr);
  *argc = static_cast<int>(args.size()) - 1;
  *argv = args.data();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  for (const std::string_view special : {"/proc", "/sys", "/dev"}) {
    if (input.find(special) != std::string_view::npos) return 0;
  }
  try {
    CheckLoaded(ParseTopology(input, kFile), input);
  } catch (const TopologyError& e) {
    const std::string what = e.what();
    if (what.rfind(kFile.string() + ":", 0) != 0) Abort("message does not start with the file", what, input);
    if (e.line() < 0 || e.column() < 0 || (e.line() > 0) != (e.column() > 0))
      Abort("bad location", what, input);
    if (e.reason().empty()) Abort("no reason", what, input);
  }
  return 0;
}
