#include "orchestrator/broker/broker.hpp"

#include <stdexcept>
#include <utility>

#include "orchestrator/broker/virtual_bus.hpp"

namespace canfleet::broker {

Broker::Broker(Scheduler& scheduler) : scheduler_(scheduler), ports_(1) {}

Broker::~Broker() = default;

void Broker::AddBus(const BusConfig& config) {
  for (const auto& bus : buses_)
    if (bus->Config().name == config.name)
      throw std::invalid_argument("bus " + config.name + " already exists");
  buses_.push_back(std::make_unique<detail::VirtualBus>(scheduler_, config));
}

detail::VirtualBus& Broker::FindBus(std::string_view name) const {
  for (const auto& bus : buses_)
    if (bus->Config().name == name) return *bus;
  throw std::invalid_argument("unknown bus " + std::string(name));
}

const Broker::PortRef* Broker::FindPort(PortId id) const {
  if (id >= ports_.size() || ports_[id].port == nullptr) return nullptr;
  return &ports_[id];
}

PortId Broker::Attach(std::string_view bus, std::string port_name, PortSink& sink, AttachOptions options) {
  detail::VirtualBus& target = FindBus(bus);
  const auto id = static_cast<PortId>(ports_.size());
  detail::Port& port = target.Attach(id, std::move(port_name), sink, options);
  ports_.push_back({&target, &port});
  return id;
}

bool Broker::Detach(PortId id) {
  const PortRef* ref = FindPort(id);
  if (ref == nullptr) return false;
  const PortRef copy = *ref;
  ports_[id] = {};  // first: a sink called during the detach sees the port as gone
  copy.bus->Detach(*copy.port);
  return true;
}

std::size_t Broker::Submit(PortId id, std::span<const CanFrame> frames) {
  const PortRef* ref = FindPort(id);
  if (ref == nullptr) return 0;
  return ref->bus->Submit(*ref->port, frames);
}

bool Broker::RecoverBusOff(PortId id) {
  const PortRef* ref = FindPort(id);
  if (ref == nullptr) return false;
  return ref->bus->RecoverBusOff(*ref->port);
}

bool Broker::SetPortBitrate(PortId id, std::uint32_t bitrate) {
  const PortRef* ref = FindPort(id);
  if (ref == nullptr) return false;
  return ref->bus->SetBitrate(*ref->port, bitrate);
}

FaultStage& Broker::Faults(std::string_view bus) {
  return FindBus(bus).Faults();
}

BusStats Broker::Stats(std::string_view bus, std::size_t top_ids) const {
  return FindBus(bus).Stats(top_ids);
}

PortStats Broker::Port(PortId id) const {
  const PortRef* ref = FindPort(id);
  if (ref == nullptr) throw std::invalid_argument("unknown port " + std::to_string(id));
  return ref->bus->StatsOf(*ref->port);
}

std::vector<PortStats> Broker::Ports(std::string_view bus) const {
  const detail::VirtualBus& b = FindBus(bus);
  std::vector<PortStats> out;
  for (const detail::Port* p : b.Ports())
    out.push_back(b.StatsOf(*p));
  return out;
}

std::optional<PortId> Broker::NewestPortNamed(std::string_view bus, std::string_view name) const {
  std::optional<PortId> found;
  for (const detail::Port* p : FindBus(bus).Ports())
    if (p->name == name) found = p->id;  // attach order: the last one is the newest
  return found;
}

void Broker::Outlook(std::string_view bus, BusOutlook& out) const {
  FindBus(bus).Outlook(out);
}

std::vector<std::string> Broker::Buses() const {
  std::vector<std::string> names;
  for (const auto& bus : buses_)
    names.push_back(bus->Config().name);
  return names;
}

}  // namespace canfleet::broker
