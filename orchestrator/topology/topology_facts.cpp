#include "orchestrator/topology/topology_facts.hpp"

#include <algorithm>
#include <sstream>

#include "node/canopen/eds/eds_error.hpp"

namespace canfleet::topology::detail {

namespace {

constexpr std::size_t kMaxNameLength = 64;

}  // namespace

std::string Quote(std::string_view text) {
  return canopen::QuoteForError(text);
}

std::string Hex(std::uint32_t value) {
  std::ostringstream out;
  out << std::hex << std::uppercase;
  out.width(4);
  out.fill('0');
  out << value;
  return out.str() + "h";
}

std::string PortsText(std::size_t ports) {
  std::string names;
  for (std::size_t p = 1; p <= ports; ++p)
    names += (p == 1 ? "CAN" : ", CAN") + std::to_string(p);
  return std::to_string(ports) + (ports == 1 ? " CAN port (" : " CAN ports (") + names + ")";
}

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

std::string BusNameProblem(std::string_view name) {
  if (std::string problem = NameProblem(name); !problem.empty()) return problem;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '-' || c == '.';
    if (!ok) return Quote(name) + " may only have letters, digits, '_', '-' and '.'";
  }
  return "";
}

namespace {

bool IsIdentifier(std::string_view text) {
  if (text.empty()) return false;
  const char first = text.front();
  if (!((first >= 'a' && first <= 'z') || (first >= 'A' && first <= 'Z'))) return false;
  return std::all_of(text.begin(), text.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
}

}  // namespace

bool LooksLikeSignalName(std::string_view name) {
  const std::size_t dot = name.find('.');
  if (dot == std::string_view::npos) return false;
  return IsIdentifier(name.substr(0, dot)) && IsIdentifier(name.substr(dot + 1));
}

fs::path TopologyFacts::Resolve(const std::string& path) const {
  const fs::path p(path);
  return (p.is_absolute() ? p : dir / p).lexically_normal();
}

const NodeFacts* TopologyFacts::FindNode(std::string_view name) const {
  for (const NodeFacts& n : nodes) {
    if (n.name == name) return &n;
  }
  return nullptr;
}

std::string TopologyFacts::BusNames() const {
  std::string out;
  for (const Bus& bus : spec.bus())
    out += (out.empty() ? "" : ", ") + bus.name();
  return out;
}

const NodeFacts& TopologyFacts::RequireNode(const Scope& s, std::string_view field,
                                            const std::string& name) const {
  if (name.empty()) s.Fail(field, "required: a node of the topology");
  if (const NodeFacts* node = FindNode(name)) return *node;
  s.Fail(field, "unknown node " + Quote(name));
}

void TopologyFacts::CheckOnBus(const Scope& s, std::string_view field, int index, const NodeFacts& node,
                               const std::string& bus) const {
  if (!node.IdOn(bus)) s.Fail(field, index, "node " + node.name + " is not on bus " + bus);
}

}  // namespace canfleet::topology::detail
