#include "orchestrator/topology/topology_loader.hpp"

#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/text_format.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

#include "bus/wire/endpoint.hpp"
#include "node/canopen/eds/eds_error.hpp"
#include "node/canopen/eds/eds_reader.hpp"
#include "node/canopen/od/object_dictionary.hpp"
#include "node/devices/eds_dictionary.hpp"
#include "node/devices/registry.hpp"
#include "orchestrator/control/sdo_value.hpp"

namespace canfleet::topology {

namespace {

namespace fs = std::filesystem;
namespace pb = google::protobuf;
using Tree = pb::TextFormat::ParseInfoTree;

constexpr std::uint32_t kDefaultBitrate = 500000;
constexpr std::uint32_t kMinBitrate = 10000;
constexpr std::uint32_t kMaxBitrate = 1000000;
constexpr std::string_view kDefaultControl = "tcp://127.0.0.1:29700";
constexpr std::string_view kDefaultListen = "tcp://127.0.0.1:29600";
constexpr std::uint32_t kDefaultBackoffMs = 500;
constexpr std::string_view kDefaultLogLevel = "info";
constexpr std::uint32_t kUnconfiguredNodeId = 255;  // an LSS slave without a node-ID
constexpr int kMaxHeartbeatConsumers = 127;
constexpr std::size_t kMaxNameLength = 64;
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{16} << 20;
// The schema nests four deep; anything deeper is not a topology (and must not exhaust the stack).
constexpr int kRecursionLimit = 32;

// ---------------------------------------------------------------------------------------------
// Small text helpers

std::string Quote(std::string_view text) {
  return canopen::QuoteForError(text);
}

// "1400h", as CiA documents write object indices.
std::string Hex(std::uint32_t value) {
  std::ostringstream out;
  out << std::hex << std::uppercase;
  out.width(4);
  out.fill('0');
  out << value;
  return out.str() + "h";
}

std::string HexId(std::uint32_t value) {
  std::ostringstream out;
  out << "0x" << std::hex << std::uppercase << value;
  return out.str();
}

std::string PortsText(std::size_t ports) {
  return std::to_string(ports) + (ports == 1 ? " CAN port" : " CAN ports");
}

// A name that can be a folder, a command-line word and a control-API key: printable ASCII
// without spaces, slashes or backslashes, not "." or "..". Returns what is wrong, or "".
std::string NameProblem(std::string_view name) {
  if (name.empty()) return "must not be empty";
  if (name.size() > kMaxNameLength) return "is longer than " + std::to_string(kMaxNameLength) + " characters";
  if (name == "." || name == "..") return "cannot be \".\" or \"..\"";
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (u <= 0x20 || u >= 0x7F) return Quote(name) + " has a space or a character other than printable ASCII";
    if (c == '/' || c == '\\') return Quote(name) + " has a slash";
  }
  return "";
}

// Bus names also appear in "--bus can0@tcp://..." and socketcand's "< open can0 >": letters,
// digits, '_', '-', '.'.
std::string BusNameProblem(std::string_view name) {
  if (std::string problem = NameProblem(name); !problem.empty()) return problem;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '-' || c == '.';
    if (!ok) return Quote(name) + " may only have letters, digits, '_', '-' and '.'";
  }
  return "";
}

bool IsIdentifier(std::string_view text) {
  if (text.empty()) return false;
  const char first = text.front();
  if (!((first >= 'a' && first <= 'z') || (first >= 'A' && first <= 'Z'))) return false;
  return std::all_of(text.begin(), text.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
}

// "AIN1.voltage_mV": CHANNEL.quantity, both identifiers.
bool LooksLikeSignalName(std::string_view name) {
  const std::size_t dot = name.find('.');
  if (dot == std::string_view::npos) return false;
  return IsIdentifier(name.substr(0, dot)) && IsIdentifier(name.substr(dot + 1));
}

// ---------------------------------------------------------------------------------------------
// Locations

struct Loc {
  int line = 1;  // 1-based
  int column = 1;
};

// Where syntax errors go: the first one wins (the parser stops there anyway).
class FirstErrorCollector final : public pb::io::ErrorCollector {
 public:
  void AddError(int line, pb::io::ColumnNumber column, const std::string& message) override {
    if (error_) return;
    error_ = true;
    line_ = line + 1;
    column_ = column + 1;
    message_ = message;
  }
  bool error() const { return error_; }
  int line() const { return line_; }
  int column() const { return column_; }
  const std::string& message() const { return message_; }

 private:
  bool error_ = false;
  int line_ = 0;
  int column_ = 0;
  std::string message_;
};

// One message of the parsed file: its path ("node[2].heartbeat"), where it starts, and its parse
// info tree (null when the text did not spell it out). Everything needed to name a field in an
// error.
class Scope {
 public:
  Scope(const std::string* file, const pb::Message* message, const Tree* tree, std::string path, Loc loc)
      : file_(file), message_(message), tree_(tree), path_(std::move(path)), loc_(loc) {}

  Loc loc() const { return loc_; }
  const std::string& path() const { return path_; }

  // Where the index-th value of `field` is (-1 or any index for a singular field); the scope's own
  // start when the text does not have it. Values written as a list ("node_id: [5, 6]") share one
  // location: a missing index falls back to the nearest earlier one.
  Loc At(std::string_view field, int index = -1) const {
    const pb::FieldDescriptor* fd = Field(field);
    if (tree_ == nullptr) return loc_;
    if (!fd->is_repeated()) {
      const auto l = tree_->GetLocation(fd, -1);
      return l.line >= 0 ? Loc{l.line + 1, l.column + 1} : loc_;
    }
    for (int i = std::max(index, 0); i >= 0; --i) {
      const auto l = tree_->GetLocation(fd, i);
      if (l.line >= 0) return {l.line + 1, l.column + 1};
    }
    return loc_;
  }

  // "node[2].node_id"; a repeated field's index is shown unless it holds a single scalar.
  std::string PathOf(std::string_view field, int index = -1) const {
    std::string out = path_.empty() ? std::string(field) : path_ + "." + std::string(field);
    const pb::FieldDescriptor* fd = Field(field);
    if (fd->is_repeated() && index >= 0) {
      const bool single_scalar = fd->cpp_type() != pb::FieldDescriptor::CPPTYPE_MESSAGE &&
                                 message_->GetReflection()->FieldSize(*message_, fd) == 1;
      if (!single_scalar) out += "[" + std::to_string(index) + "]";
    }
    return out;
  }

  // The scope of a nested message held by `field` (its index-th value when repeated).
  Scope Child(std::string_view field, const pb::Message& child, int index = -1) const {
    const pb::FieldDescriptor* fd = Field(field);
    const Tree* nested = nullptr;
    if (tree_ != nullptr) nested = tree_->GetTreeForNested(fd, fd->is_repeated() ? std::max(index, 0) : -1);
    std::string path = path_.empty() ? std::string(field) : path_ + "." + std::string(field);
    if (fd->is_repeated()) path += "[" + std::to_string(std::max(index, 0)) + "]";
    return Scope(file_, &child, nested, std::move(path), At(field, index));
  }

  [[noreturn]] void Fail(std::string_view field, int index, std::string reason) const {
    const Loc l = At(field, index);
    throw TopologyError(*file_, l.line, l.column, PathOf(field, index), std::move(reason));
  }
  [[noreturn]] void Fail(std::string_view field, std::string reason) const {
    Fail(field, -1, std::move(reason));
  }
  // An error about the message as a whole (a missing field is named by the caller's reason).
  [[noreturn]] void FailHere(std::string reason) const {
    throw TopologyError(*file_, loc_.line, loc_.column, path_.empty() ? "topology" : path_,
                        std::move(reason));
  }

 private:
  const pb::FieldDescriptor* Field(std::string_view name) const {
    const pb::FieldDescriptor* fd = message_->GetDescriptor()->FindFieldByName(std::string(name));
    if (fd == nullptr) throw std::logic_error("topology loader: no field " + std::string(name));
    return fd;
  }

  const std::string* file_;
  const pb::Message* message_;
  const Tree* tree_;
  std::string path_;
  Loc loc_;
};

std::string LineRef(const Loc& loc) {
  return "line " + std::to_string(loc.line);
}

// ---------------------------------------------------------------------------------------------
// The loader

// What validation learned about one node, for cross-checks and for the defaults.
struct NodeFacts {
  int index = 0;
  std::string name;
  Loc loc;
  std::size_t ports = 1;
  std::string kind;                   // "quad-controller", or "generic node" for an EDS-only one
  std::vector<std::uint32_t> ids;     // one per port (expanded)
  std::vector<Loc> id_locs;           // where each port's node-ID is written
  std::vector<std::string> buses;     // one per port
  fs::path state_dir;                 // resolved
  fs::path eds;                       // resolved, or empty
  fs::path dcf;                       // resolved, or empty
  const devices::DeviceInfo* variant = nullptr;  // the catalog entry, or null for a generic node
  devices::SimulatedIo* io = nullptr;  // the variant's signals (Loader::signals_): io checks set them
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

class Loader {
 public:
  Loader(std::string display, fs::path file) : display_(std::move(display)), file_(std::move(file)) {
    dir_ = file_.parent_path();
  }

  LoadedTopology Run(std::string_view text) {
    Parse(text);
    const Scope root(&display_, &spec_, &tree_, "", Loc{1, 1});
    CheckTopology(root);
    CheckOrchestrator(root);
    CheckBuses(root);
    CheckNodes(root);
    CheckHeartbeats(root);
    CheckScenario(root);
    ApplyDefaults();
    return LoadedTopology{std::move(spec_), file_};
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

  fs::path Resolve(const std::string& path) const {
    const fs::path p(path);
    return (p.is_absolute() ? p : dir_ / p).lexically_normal();
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
    state_root_ = o.state_root().empty() ? (dir_ / ".canfleet" / spec_.name()).lexically_normal()
                                         : Resolve(o.state_root());
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
      const auto [it, fresh] = buses_.emplace(bus.name(), BusFacts{i, s.At("name")});
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

  std::string BusNames() const {
    std::string out;
    for (const Bus& bus : spec_.bus())
      out += (out.empty() ? "" : ", ") + bus.name();
    return out;
  }

  // ---- nodes ------------------------------------------------------------------------------------

  void CheckNodes(const Scope& root) {
    // (bus, node-ID) -> index into nodes_ and the port
    std::map<std::pair<std::string, std::uint32_t>, std::pair<std::size_t, std::size_t>> used_ids;
    std::map<fs::path, std::size_t> state_dirs;
    for (int i = 0; i < spec_.node_size(); ++i) {
      const Node& node = spec_.node(i);
      const Scope s = root.Child("node", node, i);
      NodeFacts facts;
      facts.index = i;
      facts.name = node.name();
      facts.loc = s.loc();

      if (node.name().empty()) s.Fail("name", "required: the node's name (\"quad-5\")");
      if (std::string problem = NameProblem(node.name()); !problem.empty()) s.Fail("name", problem);
      if (const NodeFacts* other = FindNode(node.name()))
        s.Fail("name", "node " + node.name() + " is already defined (node[" + std::to_string(other->index) +
                           "], " + LineRef(other->loc) + ")");

      CheckDevice(s, node, facts);
      CheckBusesOfNode(s, node, facts);
      CheckNodeIds(s, node, facts);
      for (std::size_t p = 0; p < facts.ports; ++p) {
        const auto key = std::make_pair(facts.buses[p], facts.ids[p]);
        if (facts.ids[p] == kUnconfiguredNodeId) continue;  // LSS slaves waiting for an ID may share 255
        const auto [it, fresh] = used_ids.emplace(key, std::make_pair(nodes_.size(), p));
        if (!fresh) {
          const auto [other_node, other_port] = it->second;
          const NodeFacts& other =
              other_node < nodes_.size() ? nodes_[other_node] : facts;  // or its own port
          s.Fail("node_id", IdIndex(node, p),
                 node.name() + " has node-ID " + std::to_string(facts.ids[p]) + " on bus " + facts.buses[p] +
                     ", already used by node " + other.name + " (" + LineRef(other.id_locs[other_port]) +
                     ")");
        }
      }
      CheckUnconfiguredSerials(s, node, facts);

      facts.state_dir = node.state_dir().empty() ? (state_root_ / node.name()).lexically_normal()
                                                 : Resolve(node.state_dir());
      const auto [dir, fresh_dir] = state_dirs.emplace(facts.state_dir, nodes_.size());
      if (!fresh_dir)
        s.Fail("state_dir", "folder " + facts.state_dir.string() + " is already the state folder of node " +
                                nodes_[dir->second].name);

      CheckIo(s, node, facts);
      for (int k = 0; k < node.sdo_size(); ++k) {
        const SdoWrite& w = node.sdo(k);
        const Scope ws = s.Child("sdo", w, k);
        CheckSdo(ws, facts, w.index(), w.subindex(), w.type(), w.value(), w.port());
      }
      if (node.heartbeat().producer_ms() > 0xFFFF)
        s.Child("heartbeat", node.heartbeat())
            .Fail("producer_ms",
                  std::to_string(node.heartbeat().producer_ms()) + " does not fit 1017h (at most 65535 ms)");
      facts.producer_ms = node.heartbeat().producer_ms();

      const Restart& restart = node.restart();
      const Scope rs = s.Child("restart", restart);
      if (!Restart::Policy_IsValid(restart.policy()))
        rs.Fail("policy", "unknown policy " + std::to_string(restart.policy()));
      if (node.external() && restart.policy() != Restart::NEVER)
        rs.Fail("policy",
                "node " + node.name() + " is external (started elsewhere): it cannot be restarted from here");

      static const std::set<std::string, std::less<>> kLevels = {"trace", "debug",    "info", "warn",
                                                                 "error", "critical", "off"};
      if (!node.log_level().empty() && !kLevels.contains(node.log_level()))
        s.Fail("log_level", Quote(node.log_level()) +
                                " is not a log level (trace, debug, info, warn, error, critical, off)");

      nodes_.push_back(std::move(facts));
    }
  }

  const NodeFacts* FindNode(std::string_view name) const {
    for (const NodeFacts& n : nodes_) {
      if (n.name == name) return &n;
    }
    return nullptr;
  }

  void CheckDevice(const Scope& s, const Node& node, NodeFacts& facts) {
    if (node.device().empty() && node.eds().empty())
      s.FailHere("node " + node.name() + " needs device (a variant: " + devices::KnownDeviceNames() +
                 ") or eds (an EDS file for a generic node)");
    if (!node.eds().empty()) {
      facts.eds = Resolve(node.eds());
      CheckFile(s, "eds", node.eds(), facts.eds);
    }
    if (!node.dcf().empty()) {
      facts.dcf = Resolve(node.dcf());
      CheckFile(s, "dcf", node.dcf(), facts.dcf);
      try {
        (void)canopen::ReadEds(facts.dcf);
      } catch (const std::exception& e) {
        s.Fail("dcf", e.what());
      }
    }
    if (!node.device().empty()) {
      const devices::DeviceInfo* info = devices::FindDevice(node.device());
      if (info == nullptr)
        s.Fail("device", "unknown device " + Quote(node.device()) + " (known: " + devices::KnownDeviceNames() + ")");
      facts.ports = info->ports;
      facts.kind = std::string(info->name);
      facts.variant = info;
    } else {
      facts.ports = 1;
      facts.kind = "generic node (" + facts.eds.filename().string() + ")";
    }
    // The catalog's signals and dictionaries check io and sdo; no device is created for that.
    try {
      std::unique_ptr<devices::SimulatedIo>& io = signals_[node.device()];
      if (!io) io = facts.variant ? devices::SignalsOf(*facts.variant) : std::make_unique<devices::SimulatedIo>();
      facts.io = io.get();
      facts.dictionaries = Dictionaries(facts.variant, facts.ports, facts.eds);
    } catch (const std::exception& e) {
      s.Fail(node.eds().empty() ? "device" : "eds", e.what());
    }
  }

  // The dictionaries (one per port) of a node's device, built once per process for each variant
  // and EDS file (a fleet of a hundred Quads or I/O modules loads in one go): a variant's own EDS
  // is compiled in; an EDS file is known by its path, size and modification time, so an edited
  // file is read again.
  static std::shared_ptr<const std::vector<canopen::ObjectDictionary>> Dictionaries(
      const devices::DeviceInfo* variant, std::size_t ports, const fs::path& eds) {
    static std::mutex mutex;
    static std::map<std::string, std::shared_ptr<const std::vector<canopen::ObjectDictionary>>> built;
    constexpr std::size_t kMaxBuilt = 64;
    std::string key = variant ? std::string(variant->name) : std::string();
    if (!eds.empty()) {
      std::error_code size_error, time_error;
      const auto size = fs::file_size(eds, size_error);
      const auto time = fs::last_write_time(eds, time_error);
      if (size_error || time_error)
        key.clear();  // not cached: Build says what is wrong
      else
        key += "\n" + eds.string() + "\n" + std::to_string(size) + "\n" +
               std::to_string(time.time_since_epoch().count());
    }
    if (!key.empty()) {
      const std::lock_guard lock(mutex);
      if (const auto it = built.find(key); it != built.end()) return it->second;
    }
    auto dictionaries = std::make_shared<std::vector<canopen::ObjectDictionary>>(ports);
    for (std::size_t p = 0; p < ports; ++p)
      (*dictionaries)[p] = variant ? devices::VariantDictionary(*variant, eds) : devices::DictionaryFromEdsFile(eds);
    if (!key.empty()) {
      const std::lock_guard lock(mutex);
      if (built.size() >= kMaxBuilt) built.clear();
      built.emplace(key, dictionaries);
    }
    return dictionaries;
  }

  static void CheckFile(const Scope& s, std::string_view field, const std::string& given,
                        const fs::path& resolved) {
    std::error_code ec;
    const fs::file_status status = fs::status(resolved, ec);
    if (ec || !fs::exists(status))
      s.Fail(field, Quote(given) + ": no such file (looked for " + resolved.string() + ")");
    if (!fs::is_regular_file(status))
      s.Fail(field, Quote(given) + ": not a regular file (" + resolved.string() + ")");
  }


  void CheckBusesOfNode(const Scope& s, const Node& node, NodeFacts& facts) {
    if (node.bus_size() == 0)
      s.FailHere("node " + node.name() + " needs bus: " + PortsText(facts.ports) + ", so " +
                 std::to_string(facts.ports) + " bus name(s) (" + BusNames() + ")");
    if (static_cast<std::size_t>(node.bus_size()) != facts.ports)
      s.Fail("bus", 0,
             facts.kind + " has " + PortsText(facts.ports) + ", so node " + node.name() + " needs " +
                 std::to_string(facts.ports) + (facts.ports == 1 ? " bus" : " buses") + "; " +
                 std::to_string(node.bus_size()) + " given");
    for (int b = 0; b < node.bus_size(); ++b) {
      if (!buses_.contains(node.bus(b)))
        s.Fail("bus", b, "unknown bus " + Quote(node.bus(b)) + " (the topology's buses: " + BusNames() + ")");
      facts.buses.push_back(node.bus(b));
    }
  }

  static void CheckNodeIds(const Scope& s, const Node& node, NodeFacts& facts) {
    if (node.node_id_size() == 0)
      s.FailHere("node " + node.name() + " needs node_id (1..127, or 255 for an LSS slave)");
    if (node.node_id_size() != 1 && static_cast<std::size_t>(node.node_id_size()) != facts.ports)
      s.Fail("node_id", 0,
             "give one node-ID, or one per port (" + PortsText(facts.ports) + "); " +
                 std::to_string(node.node_id_size()) + " given");
    for (int k = 0; k < node.node_id_size(); ++k) {
      const std::uint32_t id = node.node_id(k);
      if ((id < 1 || id > 127) && id != kUnconfiguredNodeId)
        s.Fail("node_id", k,
               std::to_string(id) + " is not a node-ID (1..127, or 255 for an unconfigured LSS slave)");
    }
    for (std::size_t p = 0; p < facts.ports; ++p) {
      facts.ids.push_back(node.node_id(IdIndex(node, p)));
      facts.id_locs.push_back(s.At("node_id", IdIndex(node, p)));
    }
  }

  // Which node_id entry port `port` uses: the only one, or its own.
  static int IdIndex(const Node& node, std::size_t port) {
    return node.node_id_size() == 1 ? 0 : static_cast<int>(port);
  }

  // Unconfigured LSS slaves on one bus are told apart by their serial number (1018h sub 4).
  void CheckUnconfiguredSerials(const Scope& s, const Node& node, const NodeFacts& facts) const {
    for (std::size_t p = 0; p < facts.ports; ++p) {
      if (facts.ids[p] != kUnconfiguredNodeId) continue;
      for (const NodeFacts& other : nodes_) {
        const auto other_id = other.IdOn(facts.buses[p]);
        if (!other_id || *other_id != kUnconfiguredNodeId) continue;
        const Node& o = spec_.node(other.index);
        if (o.serial() == node.serial())
          s.Fail("serial", node.name() + " and " + other.name +
                               " are both unconfigured (node-ID 255) on bus " + facts.buses[p] +
                               " with serial " + std::to_string(node.serial()) +
                               ": LSS tells them apart by serial, give each its own");
      }
    }
  }

  void CheckIo(const Scope& s, const Node& node, NodeFacts& facts) {
    // Map entries in the order the file gives them (reflection keeps the parsed order), so a
    // problem names the right line; a key given twice would silently keep only the last.
    const pb::Reflection* reflection = node.GetReflection();
    const pb::FieldDescriptor* io = node.GetDescriptor()->FindFieldByName("io");
    const int count = reflection->FieldSize(node, io);
    std::map<std::string, int> seen;
    for (int k = 0; k < count; ++k) {
      const pb::Message& entry = reflection->GetRepeatedMessage(node, io, k);
      const pb::FieldDescriptor* key_fd = entry.GetDescriptor()->FindFieldByName("key");
      const pb::FieldDescriptor* value_fd = entry.GetDescriptor()->FindFieldByName("value");
      const std::string key = entry.GetReflection()->GetString(entry, key_fd);
      const std::string value = entry.GetReflection()->GetString(entry, value_fd);
      const Scope es = s.Child("io", entry, k);
      const auto [it, fresh] = seen.emplace(key, k);
      if (!fresh) es.Fail("key", Quote(key) + " is already set by io[" + std::to_string(it->second) + "]");
      CheckIoSet(es, "key", "value", facts, key, value);
    }
  }

  // An input of the node's device set to `value` (node io and scenario io steps).
  static void CheckIoSet(const Scope& s, std::string_view name_field, std::string_view value_field,
                         NodeFacts& facts, const std::string& name, const std::string& value) {
    if (!LooksLikeSignalName(name))
      s.Fail(name_field, Quote(name) + " is not a signal name (CHANNEL.quantity, e.g. AIN1.voltage_mV)");
    if (value.empty()) s.Fail(value_field, "required: the value to set " + name + " to");
    devices::SimulatedIo& io = *facts.io;
    const devices::IoSignal* signal = io.Find(name);
    if (signal == nullptr) {
      if (io.Signals().empty())
        s.Fail(name_field, "node " + facts.name + " is a " + facts.kind + ": it has no simulated I/O");
      std::string inputs;
      for (const auto& sig : io.Signals()) {
        if (sig->direction() == devices::IoDirection::kInput)
          inputs += (inputs.empty() ? "" : ", ") + sig->name();
      }
      s.Fail(name_field, facts.kind + " has no signal " + Quote(name) + " (its inputs: " + inputs + ")");
    }
    if (signal->direction() != devices::IoDirection::kInput)
      s.Fail(name_field, name + " is an output of " + facts.kind + "; only inputs can be set");
    const devices::IoStatus status = io.SetText(name, value);
    if (!status.ok()) s.Fail(value_field, status.error);
  }

  // An SDO write to the node (node sdo lists and scenario sdo steps): the request is well-formed
  // and the node's dictionary has a writable object of that size there.
  static void CheckSdo(const Scope& s, const NodeFacts& facts, std::uint32_t index, std::uint32_t subindex,
                       const std::string& type_name, const std::string& value, std::uint32_t port) {
    if (index < 1 || index > 0xFFFF)
      s.Fail("index", std::to_string(index) + " is not an object index (1..0xFFFF)");
    if (subindex > 255) s.Fail("subindex", std::to_string(subindex) + " is not a sub-index (0..255)");
    if (type_name.empty()) s.Fail("type", "required: one of " + std::string(control::SdoTypeNames()));
    const std::optional<control::SdoType> type = control::ParseSdoType(type_name);
    if (!type)
      s.Fail("type", Quote(type_name) + " is not a type (" + std::string(control::SdoTypeNames()) + ")");
    if (value.empty()) s.Fail("value", "required: the value to write");
    try {
      (void)control::EncodeSdoValue(*type, value);
    } catch (const std::exception& e) {
      s.Fail("value", e.what());
    }
    const std::size_t type_size = control::SdoTypeSize(*type);
    if (port >= facts.ports)
      s.Fail("port", "port " + std::to_string(port) + " does not exist: " + facts.name + " has " +
                         PortsText(facts.ports) + " (0-based)");
    const canopen::ObjectDictionary& od = facts.dictionaries->at(port);
    const auto idx = static_cast<std::uint16_t>(index);
    const auto sub = static_cast<std::uint8_t>(subindex);
    const std::string where = Hex(index) + " sub " + std::to_string(subindex);
    if (od.Find(idx) == nullptr) s.Fail("index", facts.kind + " has no object " + Hex(index));
    const canopen::SubObject* object = od.Find(idx, sub);
    if (object == nullptr) s.Fail("subindex", facts.kind + " has no " + where);
    if (object->access == canopen::Access::kRo || object->access == canopen::Access::kConst)
      s.Fail("index", where + " (" + object->name + ") of " + facts.kind + " is read-only");
    const std::optional<std::size_t> size = canopen::FixedSize(object->type);
    if (size && type_size != *size)
      s.Fail("type", type_name + " is " + std::to_string(type_size) + " byte(s) but " + where + " (" +
                         object->name + ") is " + std::to_string(*size));
    if (!size && type_size != 0)
      s.Fail("type", where + " (" + object->name + ") has a variable length: write it as vs, os or d");
  }

  // ---- heartbeats -------------------------------------------------------------------------------

  void CheckHeartbeats(const Scope& root) {
    for (NodeFacts& facts : nodes_) {
      const Node& node = spec_.node(facts.index);
      const Scope s = root.Child("node", node, facts.index).Child("heartbeat", node.heartbeat());
      const Heartbeat& hb = node.heartbeat();
      if (hb.consumer_size() > kMaxHeartbeatConsumers)
        s.Fail("consumer", kMaxHeartbeatConsumers, "at most 127 heartbeat consumers (1016h sub 1..127)");
      const canopen::Object* entries = facts.dictionaries->front().Find(0x1016);
      const int capacity = entries == nullptr
                               ? 0
                               : static_cast<int>(entries->subs.size()) - (entries->subs.contains(0) ? 1 : 0);
      if (hb.consumer_size() > capacity)
        s.Fail("consumer", capacity,
               facts.kind + " has " + std::to_string(capacity) + " heartbeat consumer entries (1016h); " +
                   std::to_string(hb.consumer_size()) + " given");
      std::map<std::uint32_t, int> consumed;
      for (int k = 0; k < hb.consumer_size(); ++k) {
        const HeartbeatConsumer& c = hb.consumer(k);
        const Scope cs = s.Child("consumer", c, k);
        std::uint32_t id = c.node_id();
        if (!c.node().empty()) {
          const NodeFacts* target = FindNode(c.node());
          if (target == nullptr) cs.Fail("node", "unknown node " + Quote(c.node()));
          if (target == &facts) cs.Fail("node", node.name() + " cannot consume its own heartbeat");
          std::optional<std::uint32_t> target_id;
          for (const std::string& bus : facts.buses) {
            if ((target_id = target->IdOn(bus))) break;
          }
          if (!target_id) cs.Fail("node", node.name() + " and " + target->name + " share no bus");
          if (*target_id == kUnconfiguredNodeId)
            cs.Fail("node", target->name + " has no node-ID yet (255): its heartbeat cannot be consumed");
          if (c.node_id() != 0 && c.node_id() != *target_id)
            cs.Fail("node_id", "node_id " + std::to_string(c.node_id()) + " is not " + target->name +
                                   "'s node-ID (" + std::to_string(*target_id) + ")");
          id = *target_id;
          CheckTimeout(cs, c);
          if (target->producer_ms > 0 && c.timeout_ms() <= target->producer_ms)
            cs.Fail("timeout_ms", std::to_string(c.timeout_ms()) + " ms is not longer than " + target->name +
                                      "'s heartbeat period (" + std::to_string(target->producer_ms) + " ms)");
        } else if (c.node_id() == 0) {
          cs.FailHere("give node (a node of the topology) or node_id (1..127)");
        } else if (c.node_id() > 127) {
          cs.Fail("node_id", std::to_string(c.node_id()) + " is not a node-ID (1..127)");
        }
        CheckTimeout(cs, c);
        const auto [it, fresh] = consumed.emplace(id, k);
        if (!fresh)
          cs.FailHere("node-ID " + std::to_string(id) + " is already consumed by consumer[" +
                      std::to_string(it->second) + "] (CiA 301 allows one entry per producer)");
        consumer_ids_[{facts.index, k}] = id;
      }
    }
  }

  static void CheckTimeout(const Scope& cs, const HeartbeatConsumer& c) {
    if (c.timeout_ms() == 0)
      cs.Fail("timeout_ms", "required, > 0 (ms without a heartbeat before the loss is reported)");
    if (c.timeout_ms() > 0xFFFF)
      cs.Fail("timeout_ms", std::to_string(c.timeout_ms()) + " does not fit 1016h (at most 65535 ms)");
  }

  // ---- scenario ---------------------------------------------------------------------------------

  void CheckScenario(const Scope& root) {
    // Steps run by time, those at the same time in file order: "earlier" for labels means that.
    std::vector<int> order(static_cast<std::size_t>(spec_.scenario_size()));
    for (std::size_t i = 0; i < order.size(); ++i)
      order[i] = static_cast<int>(i);
    std::stable_sort(order.begin(), order.end(),
                     [this](int a, int b) { return spec_.scenario(a).at_ms() < spec_.scenario(b).at_ms(); });
    std::map<std::string, int> labels;  // label -> step that injects it
    for (int i : order) {
      const Step& step = spec_.scenario(i);
      const Scope s = root.Child("scenario", step, i);
      switch (step.action_case()) {
        case Step::kInject:
          CheckInject(s.Child("inject", step.inject()), step.inject(), i, labels);
          break;
        case Step::kClear:
          CheckClear(s.Child("clear", step.clear()), step.clear(), labels);
          break;
        case Step::kIo: {
          const Scope is = s.Child("io", step.io());
          NodeFacts& facts = RequireNode(is, "node", step.io().node());
          CheckIoSet(is, "name", "value", facts, step.io().name(), step.io().value());
          break;
        }
        case Step::kNmt: {
          const Scope ns = s.Child("nmt", step.nmt());
          const control::NmtAction action = step.nmt().action();
          if (action == control::NMT_ACTION_UNSPECIFIED || !control::NmtAction_IsValid(action))
            ns.Fail("action", "required: NMT_START, NMT_STOP, NMT_PREOP, NMT_RESET or NMT_RESET_COMM");
          if (!step.nmt().node().empty()) RequireNode(ns, "node", step.nmt().node());
          break;
        }
        case Step::kSdo: {
          const control::SdoWrite& w = step.sdo();
          const Scope ws = s.Child("sdo", w);
          const NodeFacts& facts = RequireNode(ws, "node", w.node());
          CheckSdo(ws, facts, w.index(), w.subindex(), w.type(), w.value(), w.port());
          break;
        }
        case Step::ACTION_NOT_SET:
          s.FailHere("a step needs an action: inject, clear, io, nmt or sdo");
      }
    }
  }

  NodeFacts& RequireNode(const Scope& s, std::string_view field, const std::string& name) {
    if (name.empty()) s.Fail(field, "required: a node of the topology");
    for (NodeFacts& n : nodes_) {
      if (n.name == name) return n;
    }
    s.Fail(field, "unknown node " + Quote(name));
  }

  void CheckOnBus(const Scope& s, std::string_view field, int index, const NodeFacts& node,
                  const std::string& bus) const {
    if (!node.IdOn(bus)) s.Fail(field, index, "node " + node.name + " is not on bus " + bus);
  }

  void CheckInject(const Scope& s, const control::FaultSpec& f, int step,
                   std::map<std::string, int>& labels) {
    using control::FaultKind;
    if (f.kind() == control::FAULT_KIND_UNSPECIFIED || !control::FaultKind_IsValid(f.kind()))
      s.Fail(
          "kind",
          "required: a fault kind (BUS_OFF, HEARTBEAT_LOSS, RPDO_TIMEOUT, DROP, DELAY, CORRUPT, DUPLICATE, "
          "PARTITION, BABBLING_IDIOT, ERROR_PASSIVE, KILL, RESTART, POWER_CYCLE)");
    const std::string kind = control::FaultKind_Name(f.kind());
    if (!f.label().empty()) {
      const auto [it, fresh] = labels.emplace(f.label(), step);
      if (!fresh)
        s.Fail("label", "label " + Quote(f.label()) + " is already used by scenario[" +
                            std::to_string(it->second) + "]");
    }
    const NodeFacts* node = f.node().empty() ? nullptr : &RequireNode(s, "node", f.node());
    if (!f.bus().empty() && !buses_.contains(f.bus()))
      s.Fail("bus", "unknown bus " + Quote(f.bus()) + " (the topology's buses: " + BusNames() + ")");
    if (node != nullptr && !f.bus().empty()) CheckOnBus(s, "node", -1, *node, f.bus());
    const std::string bus = !f.bus().empty()  ? f.bus()
                            : node != nullptr ? node->buses.front()
                                              : std::string();

    const bool needs_node = f.kind() == control::BUS_OFF || f.kind() == control::HEARTBEAT_LOSS ||
                            f.kind() == control::RPDO_TIMEOUT || f.kind() == control::BABBLING_IDIOT ||
                            f.kind() == control::ERROR_PASSIVE || f.kind() == control::KILL ||
                            f.kind() == control::RESTART || f.kind() == control::POWER_CYCLE;
    if (needs_node && node == nullptr) s.Fail("node", "required: " + kind + " needs the node it applies to");
    const bool process_fault =
        f.kind() == control::KILL || f.kind() == control::RESTART || f.kind() == control::POWER_CYCLE;
    if (process_fault && spec_.node(node->index).external())
      s.Fail("node", "node " + node->name + " is external (started elsewhere): " + kind +
                         " cannot reach its process");

    const std::uint32_t id_limit = f.extended() ? 0x1FFFFFFF : 0x7FF;
    if (f.has_cob_id() && f.cob_id() > id_limit)
      s.Fail("cob_id",
             HexId(f.cob_id()) + " does not fit a " + (f.extended() ? "29" : "11") + "-bit identifier");
    if (f.has_mask() && f.mask() > id_limit)
      s.Fail("mask", HexId(f.mask()) + " does not fit a " + (f.extended() ? "29" : "11") + "-bit identifier");
    if (f.kind() == control::RPDO_TIMEOUT && !f.has_cob_id())
      s.Fail("cob_id",
             "required: RPDO_TIMEOUT needs the COB-ID of the RPDO that stops reaching " + node->name);
    if (!(f.probability() >= 0.0 && f.probability() <= 1.0))
      s.Fail("probability", std::to_string(f.probability()) + " is outside 0..1");
    if (f.kind() == control::DELAY && f.delay_ms() == 0 && f.jitter_ms() == 0)
      s.Fail("delay_ms", "required: DELAY needs delay_ms or jitter_ms");

    for (int r = 0; r < f.receivers_size(); ++r) {
      const NodeFacts& receiver = RequireNode(s, "receivers", f.receivers(r));
      if (!bus.empty()) CheckOnBus(s, "receivers", r, receiver, bus);
    }

    if (f.kind() == control::PARTITION) {
      if (bus.empty()) s.Fail("bus", "required: PARTITION without node needs the bus to split");
      if (f.groups_size() < 2)
        s.Fail("groups", 0,
               "PARTITION needs at least 2 groups of nodes; " + std::to_string(f.groups_size()) + " given");
      std::map<std::string, int> grouped;
      for (int g = 0; g < f.groups_size(); ++g) {
        const Scope gs = s.Child("groups", f.groups(g), g);
        if (f.groups(g).nodes_size() == 0) gs.FailHere("a group needs at least one node");
        for (int n = 0; n < f.groups(g).nodes_size(); ++n) {
          const std::string& name = f.groups(g).nodes(n);
          const NodeFacts& member = RequireNode(gs, "nodes", name);
          CheckOnBus(gs, "nodes", n, member, bus);
          const auto [it, fresh] = grouped.emplace(name, g);
          if (!fresh)
            gs.Fail("nodes", n, "node " + name + " is already in groups[" + std::to_string(it->second) + "]");
        }
      }
    } else if (f.groups_size() > 0) {
      s.Fail("groups", 0, "groups are for PARTITION only, not " + kind);
    }
  }

  static void CheckClear(const Scope& s, const control::FaultClear& c,
                         const std::map<std::string, int>& labels) {
    if (c.fault_id() != 0)
      s.Fail("fault_id", "fault ids are given out at run time: a scenario clears by label");
    if (!c.label().empty() && !labels.contains(c.label()))
      s.Fail("label", "no earlier step injects a fault labelled " + Quote(c.label()) +
                          " (steps run by at_ms, then in file order)");
  }

  // ---- defaults ---------------------------------------------------------------------------------

  void ApplyDefaults() {
    Orchestrator& o = *spec_.mutable_orchestrator();
    if (o.control().empty()) o.set_control(std::string(kDefaultControl));
    if (o.listen_size() == 0) o.add_listen(std::string(kDefaultListen));
    if (!o.has_start_nodes()) o.set_start_nodes(true);
    o.set_state_root(state_root_.string());

    for (Bus& bus : *spec_.mutable_bus()) {
      if (bus.bitrate() == 0) bus.set_bitrate(kDefaultBitrate);
    }

    for (const NodeFacts& facts : nodes_) {
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
        node.mutable_heartbeat()->mutable_consumer(k)->set_node_id(consumer_ids_.at({facts.index, k}));
    }

    for (Step& step : *spec_.mutable_scenario()) {
      if (!step.has_inject()) continue;
      control::FaultSpec& f = *step.mutable_inject();
      if (f.bus().empty() && !f.node().empty()) f.set_bus(FindNode(f.node())->buses.front());
    }
  }

  std::string display_;
  fs::path file_;
  fs::path dir_;
  Topology spec_;
  Tree tree_;
  fs::path state_root_;
  std::map<std::string, BusFacts> buses_;
  std::vector<NodeFacts> nodes_;
  // One scratch device per variant and EDS, shared by the nodes that use it: io checks only ask
  // whether a value would be accepted, and building a device per node is most of a load's time.
  std::map<std::string, std::unique_ptr<devices::SimulatedIo>> signals_;
  std::map<std::pair<int, int>, std::uint32_t> consumer_ids_;  // (node index, consumer index) -> node-ID
};

std::string FormatMessage(const std::string& file, int line, int column, const std::string& field,
                          const std::string& reason) {
  std::string out = file;
  if (line > 0) out += ":" + std::to_string(line) + ":" + std::to_string(column);
  out += ": ";
  if (!field.empty()) out += field + ": ";
  return out + reason;
}

fs::path AbsoluteFile(const fs::path& file) {
  std::error_code ec;
  fs::path absolute = fs::absolute(file, ec);
  if (ec) absolute = file;
  return absolute.lexically_normal();
}

}  // namespace

TopologyError::TopologyError(std::string file, int line, int column, std::string field, std::string reason)
    : std::runtime_error(FormatMessage(file, line, column, field, reason)),
      file_(std::move(file)),
      line_(line),
      column_(column),
      field_(std::move(field)),
      reason_(std::move(reason)) {}

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
