#include "node/devices/device_node.hpp"

#include <stdexcept>
#include <string>

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
    auto od = std::make_unique<canopen::ObjectDictionary>();
    device_->Build(p, *od);
    if (settings.serial_number) ApplySerialNumber(*od, *settings.serial_number);
    dictionaries_.push_back(std::move(od));
  }
  for (std::size_t p = 0; p < count; ++p) {
    StackSetup setup;
    PortSettings port = p < settings.ports.size() ? settings.ports[p] : PortSettings{};
    setup.options.node_id = port.node_id;
    setup.options.bit_timing_index = port.bit_timing_index;
    if (!settings.state_dir.empty())
      setup.options.state_dir =
          count == 1 ? settings.state_dir : settings.state_dir / ("port" + std::to_string(p + 1));
    device_->ConfigureStack(p, setup);
    setup.hooks = ChainHooks(std::move(setup.hooks), settings.hooks);
    stacks_.push_back(std::make_unique<canopen::CanopenStack>(
        *dictionaries_[p], *ports[p], scheduler, std::move(setup.options), std::move(setup.hooks),
        std::move(setup.policy)));
  }
  DeviceContext context{scheduler, {}};
  for (auto& stack : stacks_)
    context.stacks.push_back(stack.get());
  device_->Attach(context);
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
