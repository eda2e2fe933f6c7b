#include "node/devices/device_node.hpp"

#include <memory>
#include <stdexcept>
#include <string>

#include "node/canopen/lss/lss_protocol.hpp"
#include "node/canopen/storage/parameter_store.hpp"

namespace canfleet::devices {

namespace {

template <typename... Args>
std::function<void(Args...)> Chain(std::function<void(Args...)> a, std::function<void(Args...)> b) {
  if (!a) return b;
  if (!b) return a;
  return [a = std::move(a), b = std::move(b)](Args... args) {
    a(args...);
    b(args...);
  };
}

// 1018h sub 4 is a constant of the unit: both the value and the default (reset communication
// restores defaults) carry the serial number.
void ApplySerialNumber(canopen::ObjectDictionary& od, std::uint32_t serial) {
  canopen::SubObject* sub = od.Find(0x1018, 4);
  if (!sub) return;
  sub->default_value = canopen::EncodeLe(serial, canopen::FixedSize(sub->type).value_or(4));
  sub->default_adds_node_id = false;
  sub->value = sub->default_value;
}

/// Port `p`'s bit timing changes (LSS activate bit timing, the bit-rate object at reset): the bus
/// port follows (BusPort::SetBitRate), and `*report` (if set) is told whether it did.
canopen::StackHooks BitRateHooks(std::size_t p, BusPort& port, const DeviceNode::BitRateReport* report) {
  canopen::StackHooks hooks;
  hooks.on_bit_timing = [p, &port, report](std::uint8_t index) {
    const auto kbit = canopen::BitRateKbit(index);
    if (!kbit) return;
    const bool applied = port.SetBitRate(*kbit * 1000);
    if (*report) (*report)(p, *kbit, applied);
  };
  return hooks;
}

}  // namespace

canopen::StackHooks ChainHooks(canopen::StackHooks first, canopen::StackHooks second) {
  canopen::StackHooks h;
  h.on_reset_application =
      Chain(std::move(first.on_reset_application), std::move(second.on_reset_application));
  h.on_state_changed = Chain(std::move(first.on_state_changed), std::move(second.on_state_changed));
  h.on_comm_error = Chain(std::move(first.on_comm_error), std::move(second.on_comm_error));
  h.on_storage_issue = Chain(std::move(first.on_storage_issue), std::move(second.on_storage_issue));
  h.on_bit_timing = Chain(std::move(first.on_bit_timing), std::move(second.on_bit_timing));
  return h;
}

DeviceNode::DeviceNode(std::unique_ptr<Device> device, Scheduler& scheduler, std::vector<BusPort*> ports,
                       NodeSettings settings)
    : device_(std::move(device)) {
  if (!device_) throw std::invalid_argument("DeviceNode: no device");
  const std::size_t count = device_->PortCount();
  if (ports.size() != count) {
    throw std::invalid_argument(std::string(device_->Name()) + " has " + std::to_string(count) +
                                " CAN port(s), " + std::to_string(ports.size()) + " given");
  }
  for (std::size_t p = 0; p < count; ++p) {
    if (!ports[p]) throw std::invalid_argument("DeviceNode: port " + std::to_string(p + 1) + " is null");
    device_ports_.push_back(std::make_unique<DevicePort>(*ports[p]));
    auto od = std::make_unique<canopen::ObjectDictionary>();
    device_->Build(p, *od);
    if (settings.serial_number) ApplySerialNumber(*od, *settings.serial_number);
    dictionaries_.push_back(std::move(od));
  }
  ShareObjects();
  for (std::size_t p = 0; p < count; ++p) {
    StackSetup setup;
    PortSettings port = p < settings.ports.size() ? settings.ports[p] : PortSettings{};
    setup.options.node_id = port.node_id;
    setup.options.bit_timing_index = port.bit_timing_index;
    if (!settings.state_dir.empty())
      setup.options.state_dir =
          count == 1 ? settings.state_dir : settings.state_dir / ("port" + std::to_string(p + 1));
    device_->ConfigureStack(p, setup);
    setup.hooks = ChainHooks(ChainHooks(std::move(setup.hooks), settings.hooks),
                             BitRateHooks(p, *ports[p], &on_bit_rate_));
    stacks_.push_back(std::make_unique<canopen::CanopenStack>(
        *dictionaries_[p], *device_ports_[p], scheduler, std::move(setup.options), std::move(setup.hooks),
        std::move(setup.policy)));
  }
  ForwardSharedStorage();
  DeviceContext context{scheduler, {}, {}};
  for (std::size_t p = 0; p < count; ++p) {
    context.stacks.push_back(stacks_[p].get());
    context.ports.push_back(device_ports_[p].get());
  }
  device_->Attach(context);
}

namespace {

/// The 1010h/1011h sub-index of a parameter group (CiA 301 §7.5.2.13: 2 comm, 3 application,
/// 4 manufacturer).
std::uint8_t SubIndexOf(canopen::StoreGroup group) {
  switch (group) {
    case canopen::StoreGroup::kCommunication:
      return 2;
    case canopen::StoreGroup::kApplication:
      return 3;
    default:
      return 4;
  }
}

}  // namespace

void DeviceNode::ShareObjects() {
  const auto range = device_->SharedObjects();
  if (!range || dictionaries_.size() < 2) return;
  auto& owned = dictionaries_[0]->objects();
  for (auto it = owned.lower_bound(range->first); it != owned.end() && it->first <= range->last; ++it) {
    for (std::size_t p = 1; p < dictionaries_.size(); ++p)
      dictionaries_[p]->Borrow(it->second);
  }
}

// A 1010h/1011h command on another port also stores (restores) the shared objects, once, in port
// 1's parameter store: its groups that overlap the shared range (manufacturer 2000h-5FFFh, sub 4;
// application 6000h-9FFFh, sub 3). "All" (sub 1) covers both; "communication" (sub 2) neither.
void DeviceNode::ForwardSharedStorage() {
  const auto range = device_->SharedObjects();
  canopen::ParameterStore* primary = stacks_.empty() ? nullptr : stacks_[0]->store();
  if (!range || !primary) return;
  for (std::size_t p = 1; p < stacks_.size(); ++p) {
    for (const std::uint16_t index : {std::uint16_t{0x1010}, std::uint16_t{0x1011}}) {
      canopen::Object* object = dictionaries_[p]->Find(index);
      if (!object) continue;
      const bool store = index == 0x1010;
      const std::uint32_t signature = store ? canopen::kSaveSignature : canopen::kLoadSignature;
      for (auto& [sub_index, sub] : object->subs) {
        if (sub_index == 0 || sub_index == 2) continue;
        sub.AddValidator([primary, store, signature, range = *range](const canopen::SubObject& s,
                                                                     std::span<const std::uint8_t> data,
                                                                     canopen::Origin) {
          if (data.size() != 4 || canopen::DecodeUnsignedLe(data) != signature)
            return canopen::SdoAbort::kNone;
          for (const auto& group : canopen::ParameterGroups()) {
            const std::uint8_t group_sub = SubIndexOf(group.group);
            const bool in_command = s.sub_index == 1 || s.sub_index == group_sub ||
                                    (s.sub_index > 4 && group.group == canopen::StoreGroup::kManufacturer);
            if (!in_command || group.last < range.first || group.first > range.last) continue;
            const auto rc = store ? primary->Save(group_sub) : primary->MarkRestoreDefaults(group_sub);
            if (rc != canopen::SdoAbort::kNone) return rc;
          }
          return canopen::SdoAbort::kNone;
        });
      }
    }
  }
}

DeviceNode::~DeviceNode() {
  device_.reset();
  stacks_.clear();
}

void DeviceNode::Start() {
  for (auto& stack : stacks_)
    stack->Start();
}

}  // namespace canfleet::devices
