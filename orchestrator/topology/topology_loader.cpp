#include "orchestrator/topology/topology_loader.hpp"

#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/text_format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <sstream>
#include <system_error>
#include <utility>

#include "bus/physics/wire_model.hpp"
#include "bus/wire/endpoint.hpp"
#include "orchestrator/control/fault_kinds.hpp"
#include "orchestrator/topology/located_error.hpp"
#include "orchestrator/topology/node_checks.hpp"
#include "orchestrator/topology/port_numbering.hpp"
#include "orchestrator/topology/scenario_checks.hpp"
#include "orchestrator/topology/topology_facts.hpp"
#include "orchestrator/topology/topology_warnings.hpp"

// The loader runs the checks in order, each job in its own file: located_error (where a refusal
// points), node_checks (nodes and heartbeats), scenario_checks (the scenario); this file parses,
// checks the topology's own fields, the orchestrator and the buses, and applies the defaults; last,
// topology_warnings says what would load but cannot work, and each bus's offered load.

namespace canfleet::topology {

namespace {

using namespace detail;

constexpr std::uint32_t kDefaultBitrate = 500000;
constexpr std::string_view kDefaultControl = "tcp://127.0.0.1:29700";
constexpr std::string_view kDefaultListen = "tcp://127.0.0.1:29600";
constexpr std::uint32_t kDefaultBackoffMs = 500;
constexpr std::string_view kDefaultLogLevel = "info";
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{16} << 20;
// The schema nests four deep; anything deeper is not a topology (and must not exhaust the stack).
constexpr int kRecursionLimit = 32;

class Loader {
 public:
  Loader(std::string display, fs::path file)
      : display_(std::move(display)),
        file_(std::move(file)),
        facts_{.spec = spec_, .dir = file_.parent_path()} {}

  LoadedTopology Run(std::string_view text) {
    Parse(text);
    std::vector<TopologyWarning> warnings;  // what the checks note on the way (an old signal name)
    const Scope root(&display_, &spec_, &tree_, "", Loc{1, 1}, &warnings);
    NumberPortsAsManuals(root, spec_);  // before the checks: they read the 0-based port
    CheckTopology(root);
    CheckOrchestrator(root);
    CheckTime(root);
    CheckBuses(root);
    NodeChecks nodes(facts_);
    nodes.CheckNodes(root);
    nodes.CheckHeartbeats(root);
    ScenarioChecks(facts_).CheckScenario(root);
    ApplyDefaults();
    Feasibility feasibility = CheckFeasibility(root, facts_);
    std::vector<int> step_lines;
    for (int i = 0; i < spec_.scenario_size(); ++i)
      step_lines.push_back(root.Child("scenario", spec_.scenario(i), i).loc().line);
    warnings.insert(warnings.end(), std::make_move_iterator(feasibility.warnings.begin()),
                    std::make_move_iterator(feasibility.warnings.end()));
    return LoadedTopology{std::move(spec_), file_, std::move(step_lines), std::move(warnings),
                          std::move(feasibility.loads)};
  }

 private:
  // ---- parsing --------------------------------------------------------------------------------

  void Parse(std::string_view text) {
    if (text.size() > kMaxFileBytes)
      throw TopologyError(display_, 0, 0, "", "larger than " + std::to_string(kMaxFileBytes >> 20) + " MiB");
    FirstErrorCollector errors;
    pb::TextFormat::Parser parser;
    parser.RecordErrorsTo(&errors);
    parser.WriteLocationsTo(&tree_);
    parser.SetRecursionLimit(kRecursionLimit);
    pb::io::ArrayInputStream input(text.data(), static_cast<int>(text.size()));
    const bool ok = parser.Parse(&input, &spec_);
    if (!ok || errors.error()) {
      std::string message = errors.error() ? errors.message() : "not a valid topology";
      throw TopologyError(display_, std::max(errors.line(), 1), std::max(errors.column(), 1), "",
                          "syntax error: " + message);
    }
  }

  // ---- topology and orchestrator ----------------------------------------------------------------

  void CheckTopology(const Scope& root) {
    if (spec_.name().empty())
      root.Fail("name", "required: the topology's name (it names the state folder .canfleet/<name>)");
    if (std::string problem = NameProblem(spec_.name()); !problem.empty())
      root.Fail("name", "must be usable as a folder name: " + problem);
  }

  void CheckOrchestrator(const Scope& root) {
    const Orchestrator& o = spec_.orchestrator();
    const Scope s = root.Child("orchestrator", o);
    if (!o.control().empty()) CheckEndpoint(s, "control", -1, o.control());
    std::map<std::string, int> seen;
    for (int i = 0; i < o.listen_size(); ++i) {
      CheckEndpoint(s, "listen", i, o.listen(i));
      const auto [it, fresh] = seen.emplace(o.listen(i), i);
      if (!fresh)
        s.Fail("listen", i,
               Quote(o.listen(i)) + " is already listed as listen[" + std::to_string(it->second) + "]");
    }
    facts_.state_root = o.state_root().empty() ? (facts_.dir / ".canfleet" / spec_.name()).lexically_normal()
                                               : facts_.Resolve(o.state_root());
  }

  /// Virtual time needs paced buses (a time line) and nothing that lives in real time. An external
  /// node joins as any other, started with `canfleet-node --time virtual` wherever it runs.
  void CheckTime(const Scope& root) {
    if (!spec_.has_time()) return;
    const Time& t = spec_.time();
    const Scope s = root.Child("time", t);
    if (t.speed() < 0 || !std::isfinite(t.speed()))
      s.Fail("speed", "must be 0 (as fast as possible) or a positive factor of real time");
    if (t.mode() != Time::VIRTUAL) return;
    for (int i = 0; i < spec_.bus_size(); ++i) {
      const Bus& bus = spec_.bus(i);
      const Scope b = root.Child("bus", bus, i);
      if (bus.unpaced()) b.Fail("unpaced", "an unpaced bus has no time line: it cannot run in virtual time");
      if (bus.socketcand_port() != 0)
        b.Fail("socketcand_port", "socketcand clients live in real time: not served in virtual time");
    }
  }

  static void CheckEndpoint(const Scope& s, std::string_view field, int index, const std::string& text) {
    try {
      (void)wire::Endpoint::Parse(text);
    } catch (const std::exception& e) {
      s.Fail(field, index, e.what());
    }
  }

  // ---- buses ------------------------------------------------------------------------------------

  void CheckBuses(const Scope& root) {
    if (spec_.bus_size() == 0)
      root.Fail("bus", "at least one bus is required: bus { name: \"can0\" bitrate: 500000 }");
    std::map<std::uint32_t, int> ports;
    for (int i = 0; i < spec_.bus_size(); ++i) {
      const Bus& bus = spec_.bus(i);
      const Scope s = root.Child("bus", bus, i);
      if (bus.name().empty()) s.Fail("name", "required: the bus's name (\"can0\")");
      if (std::string problem = BusNameProblem(bus.name()); !problem.empty()) s.Fail("name", problem);
      const auto [it, fresh] = facts_.buses.emplace(bus.name(), BusFacts{i, s.At("name")});
      if (!fresh)
        s.Fail("name", "bus " + bus.name() + " is already defined (bus[" + std::to_string(it->second.index) +
                           "], " + LineRef(it->second.loc) + ")");
      if (bus.bitrate() != 0 && (bus.bitrate() < kMinBitrate || bus.bitrate() > kMaxBitrate))
        s.Fail("bitrate", std::to_string(bus.bitrate()) + " bit/s is outside " + std::to_string(kMinBitrate) +
                              ".." + std::to_string(kMaxBitrate));
      if (bus.socketcand_port() != 0) {
        if (bus.socketcand_port() > 65535)
          s.Fail("socketcand_port", std::to_string(bus.socketcand_port()) + " is not a TCP port");
        const auto [p, fresh_port] = ports.emplace(bus.socketcand_port(), i);
        if (!fresh_port)
          s.Fail("socketcand_port", "port " + std::to_string(bus.socketcand_port()) + " already serves bus " +
                                        spec_.bus(p->second).name());
      }
    }
  }

  // ---- defaults ---------------------------------------------------------------------------------

  void ApplyDefaults() {
    Orchestrator& o = *spec_.mutable_orchestrator();
    if (o.control().empty()) o.set_control(std::string(kDefaultControl));
    if (o.listen_size() == 0) o.add_listen(std::string(kDefaultListen));
    if (!o.has_start_nodes()) o.set_start_nodes(true);
    o.set_state_root(facts_.state_root.string());

    for (Bus& bus : *spec_.mutable_bus()) {
      if (bus.bitrate() == 0) bus.set_bitrate(kDefaultBitrate);
    }

    for (const NodeFacts& facts : facts_.nodes) {
      Node& node = *spec_.mutable_node(facts.index);
      node.set_state_dir(facts.state_dir.string());
      if (!facts.eds.empty()) node.set_eds(facts.eds.string());
      if (!facts.dcf.empty()) node.set_dcf(facts.dcf.string());
      node.clear_node_id();
      for (const std::uint32_t id : facts.ids)
        node.add_node_id(id);
      if (node.restart().backoff_ms() == 0) node.mutable_restart()->set_backoff_ms(kDefaultBackoffMs);
      if (node.log_level().empty()) node.set_log_level(std::string(kDefaultLogLevel));
      for (int k = 0; k < node.heartbeat().consumer_size(); ++k)
        node.mutable_heartbeat()->mutable_consumer(k)->set_node_id(facts_.consumer_ids.at({facts.index, k}));
    }

    for (Step& step : *spec_.mutable_scenario()) {
      if (!step.has_inject()) continue;
      control::FaultSpec& f = *step.mutable_inject();
      const bool takes_bus = control::TraitsOf(f.kind())->takes.Has(control::FaultOption::kBus);
      if (f.bus().empty() && !f.node().empty() && takes_bus)
        f.set_bus(facts_.FindNode(f.node())->buses.front());
    }
  }

  std::string display_;
  fs::path file_;
  Topology spec_;
  Tree tree_;
  TopologyFacts facts_;
};

fs::path AbsoluteFile(const fs::path& file) {
  std::error_code ec;
  fs::path absolute = fs::absolute(file, ec);
  if (ec) absolute = file;
  return absolute.lexically_normal();
}

}  // namespace

LoadedTopology ParseTopology(std::string_view text,
                             const std::filesystem::path& file_for_messages_and_relative_paths) {
  Loader loader(file_for_messages_and_relative_paths.string(),
                AbsoluteFile(file_for_messages_and_relative_paths));
  return loader.Run(text);
}

LoadedTopology LoadTopology(const std::filesystem::path& file) {
  const std::string display = file.string();
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (ec || !fs::exists(status)) throw TopologyError(display, 0, 0, "", "no such file");
  if (fs::is_directory(status)) throw TopologyError(display, 0, 0, "", "is a folder, not a topology file");
  const std::uintmax_t size = fs::file_size(file, ec);
  if (!ec && size > kMaxFileBytes)
    throw TopologyError(display, 0, 0, "",
                        "larger than " + std::to_string(kMaxFileBytes >> 20) + " MiB: not a topology");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw TopologyError(display, 0, 0, "", "cannot be opened for reading");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw TopologyError(display, 0, 0, "", "cannot be read");
  return ParseTopology(text.str(), file);
}

}  // namespace canfleet::topology
