#include "node/process/node_telemetry_wiring.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <unordered_map>

#include "telemetry/cli_options.hpp"
#include "telemetry/node_telemetry.hpp"

namespace canfleet::node {

void AddTelemetryOptions(CLI::App& app, TelemetrySettings& settings) {
  app.add_flag("!--no-telemetry", settings.enabled, "do not publish telemetry over DDS");
  auto* period = app.add_option_function<double>(
      "--telemetry-period",
      [&settings](double seconds) {
        settings.period = std::chrono::milliseconds(static_cast<long>(seconds * 1000.0));
      },
      "republish status and I/O at least this often, seconds (default 1)");
  period->check(CLI::Range(0.05, 3600.0));
  telemetry::AddDdsOptions(app, settings.dds, telemetry::DdsDiscovery::kMonitorsOnly);
}

namespace {

using canopen::HeartbeatConsumerStatus;
using telemetry::HeartbeatConsumerState;

HeartbeatConsumerState ToTelemetry(HeartbeatConsumerStatus::State state) {
  switch (state) {
    case HeartbeatConsumerStatus::State::kActive:
      return HeartbeatConsumerState::kActive;
    case HeartbeatConsumerStatus::State::kTimedOut:
      return HeartbeatConsumerState::kTimedOut;
    default:
      return HeartbeatConsumerState::kUnknown;
  }
}

/// The NodeStatus key of a stack: its node-ID, 0 while an LSS slave is unconfigured (IDL).
std::uint8_t KeyNodeId(const canopen::CanopenStack& stack) {
  const std::uint8_t id = stack.NodeId();
  return id >= 1 && id <= 127 ? id : 0;
}

/// Decodes an EMCY frame (CiA 301 §7.2.7.3.1): bytes 0-1 code (LE), 2 error register, 3-7 manufacturer.
telemetry::EmcyInfo DecodeEmcy(const CanFrame& frame) {
  telemetry::EmcyInfo emcy;
  const auto byte = [&](std::size_t i) -> std::uint8_t { return i < frame.dlc ? frame.data[i] : 0; };
  emcy.code = static_cast<std::uint16_t>(byte(0) | (byte(1) << 8));
  emcy.error_register = byte(2);
  for (std::size_t i = 0; i < emcy.manufacturer.size(); ++i)
    emcy.manufacturer[i] = byte(3 + i);
  // The node does not know the bus time of its own frame (the broker stamps it): 0 = unknown. The
  // DDS source timestamp carries the wall-clock time.
  emcy.bus_time = BusTime{0};
  return emcy;
}

}  // namespace

struct NodeTelemetryWiring::Impl {
  struct Port {
    std::string bus;
    std::uint8_t node_id = 0;
    telemetry::NodeStatusSnapshot status;
    std::unique_ptr<telemetry::NodeTelemetry> publisher;
  };

  explicit Impl(const TelemetrySettings& s) : settings(s), participant(s.dds) {}

  TelemetrySettings settings;
  std::string name;                    ///< --name: NodeStatus.name
  telemetry::Participant participant;  // declared first: outlives the publishers
  devices::DeviceNode* node = nullptr;
  const Scheduler* scheduler = nullptr;  ///< the node's: the uptime follows its time (virtual too)
  std::vector<Port> ports;
  std::vector<telemetry::IoChannel> input_channels;
  std::vector<telemetry::IoChannel> output_channels;
  std::vector<double> inputs;
  std::vector<double> outputs;
  /// Where each published signal's value sits: (is_input, index in inputs/outputs).
  std::unordered_map<const devices::IoSignal*, std::pair<bool, std::size_t>> io_index;
  std::optional<Timer> timer;

  telemetry::NodeTelemetryOptions PublisherOptions(const Port& port) const {
    return {.bus = port.bus,
            .node_id = port.node_id,
            .device = std::string(node->device().Name()),
            .name = name,
            .period = settings.period,
            .min_interval = std::chrono::milliseconds(20),
            .inputs = input_channels,
            .outputs = output_channels,
            .uptime_clock = scheduler};
  }

  void CollectIo() {
    for (const auto& signal : node->io().Signals()) {
      const bool input = signal->direction() == devices::IoDirection::kInput;
      auto& channels = input ? input_channels : output_channels;
      auto& values = input ? inputs : outputs;
      if (channels.size() == telemetry::kMaxIoChannels) {
        spdlog::warn("telemetry: more than {} {}s, {} is not published", telemetry::kMaxIoChannels,
                     input ? "input" : "output", signal->name());
        continue;
      }
      io_index[signal.get()] = {input, values.size()};
      // A bool's or an enum's value is the index of its word (IoSignal::Number): the publisher
      // copies the word into IoValue.text, what `canfleet io get` prints.
      std::vector<std::string> words;
      if (signal->kind() == devices::IoKind::kBool) words = {"false", "true"};
      if (signal->kind() == devices::IoKind::kEnum) words = signal->spec().choices;
      channels.push_back({signal->name(),
                          signal->kind() == devices::IoKind::kNumber ? signal->spec().unit : "",
                          std::move(words)});
      values.push_back(signal->Number());
    }
  }

  void OnIo(const devices::IoSignal& signal) {
    const auto it = io_index.find(&signal);
    if (it == io_index.end()) return;
    (it->second.first ? inputs : outputs)[it->second.second] = signal.Number();
    for (auto& port : ports)
      if (port.publisher) port.publisher->UpdateIo(inputs, outputs);
  }

  void OnEmcySent(std::size_t p, const CanFrame& frame) {
    if (p >= ports.size()) return;
    SamplePort(p);  // the EMCY changed 1001h: the status goes out with it
    if (ports[p].publisher) ports[p].publisher->PublishEmcy(DecodeEmcy(frame));
  }

  void SamplePort(std::size_t p) {
    Port& port = ports[p];
    canopen::CanopenStack& stack = node->stack(p);
    if (KeyNodeId(stack) != port.node_id) {
      // LSS gave the port a new node-ID: the old instance leaves (disposed), a new one appears.
      port.publisher.reset();
      port.node_id = KeyNodeId(stack);
      try {
        port.publisher = std::make_unique<telemetry::NodeTelemetry>(participant, PublisherOptions(port));
        port.publisher->UpdateIo(inputs, outputs);
      } catch (const std::exception& e) {  // never take the node down for its telemetry
        spdlog::error("telemetry: port {} as node {}: {}", p + 1, static_cast<int>(port.node_id), e.what());
      }
    }
    if (!port.publisher) return;
    telemetry::NodeStatusSnapshot& s = port.status;
    s.nmt_state = stack.State();
    s.error_register = stack.emcy().ErrorRegister();
    const ControllerEvent& controller = stack.Controller();
    s.controller_state = controller.state;
    s.tec = controller.tec;
    s.rec = controller.rec;
    s.heartbeat_producer_ms = static_cast<std::uint16_t>(stack.od().GetUnsigned(0x1017, 0));
    std::size_t n = 0;
    for (const HeartbeatConsumerStatus& c : stack.heartbeat_consumer().Status()) {
      if (c.state == HeartbeatConsumerStatus::State::kUnconfigured || n == s.heartbeat_consumers.size())
        continue;
      const bool heard = c.state != HeartbeatConsumerStatus::State::kWaiting ||
                         c.last_state != canopen::NmtState::kInitialising;
      s.heartbeat_consumers[n++] = {
          c.node_id,
          static_cast<std::uint16_t>(std::chrono::duration_cast<std::chrono::milliseconds>(c.period).count()),
          ToTelemetry(c.state), heard ? std::optional(c.last_state) : std::nullopt};
    }
    s.heartbeat_consumer_count = static_cast<std::uint8_t>(n);
    const canopen::PdoCounters& counters = stack.pdo().Counters();
    s.rpdo_count = counters.rpdo_received;
    s.tpdo_count = counters.tpdo_sent;
    port.publisher->UpdateStatus(s);
  }

  void SampleAll() {
    for (std::size_t p = 0; p < ports.size(); ++p)
      SamplePort(p);
  }

  void OnTimer() {
    SampleAll();
    timer->StartAfter(std::chrono::duration_cast<Duration>(settings.period));
  }
};

NodeTelemetryWiring::NodeTelemetryWiring(const TelemetrySettings& settings)
    : impl_(std::make_unique<Impl>(settings)), handle_(std::make_shared<Impl*>(impl_.get())) {
  if (settings.period <= std::chrono::milliseconds::zero())
    throw std::invalid_argument("telemetry period must be > 0");
}

NodeTelemetryWiring::~NodeTelemetryWiring() {
  *handle_ = nullptr;
}

canopen::StackHooks NodeTelemetryWiring::Hooks() {
  canopen::StackHooks hooks;
  const auto sample = [h = handle_] {
    if (*h && (*h)->node) (*h)->SampleAll();
  };
  hooks.on_state_changed = [sample](canopen::NmtState) { sample(); };
  // Controller state changes arrive as communication errors (bus-off, error passive) raised or
  // cleared; the stack has stored the controller event (state, TEC, REC) by then.
  hooks.on_comm_error = [sample](const canopen::CommError&, bool) { sample(); };
  hooks.on_reset_application = sample;
  return hooks;
}

void NodeTelemetryWiring::Attach(devices::DeviceNode& node, Scheduler& scheduler,
                                 const std::vector<std::string>& buses, const std::string& name) {
  Impl& m = *impl_;
  if (m.node) throw std::logic_error("NodeTelemetryWiring::Attach called twice");
  if (buses.size() != node.PortCount()) {
    throw std::invalid_argument("telemetry: " + std::to_string(node.PortCount()) + " port(s) but " +
                                std::to_string(buses.size()) + " bus name(s)");
  }
  for (const auto& bus : buses) {
    if (bus.empty() || bus.size() > telemetry::kMaxBusName) {
      // The IDL key is string<15>. Never take the node down for its telemetry: it runs without.
      spdlog::error("telemetry: bus name '{}' is not 1..{} characters; running without telemetry", bus,
                    telemetry::kMaxBusName);
      return;
    }
  }
  m.node = &node;
  m.scheduler = &scheduler;
  m.name = name;
  m.CollectIo();
  for (std::size_t p = 0; p < buses.size(); ++p) {
    Impl::Port port;
    port.bus = buses[p];
    port.node_id = KeyNodeId(node.stack(p));
    port.publisher = std::make_unique<telemetry::NodeTelemetry>(m.participant, m.PublisherOptions(port));
    if (!m.inputs.empty() || !m.outputs.empty()) port.publisher->UpdateIo(m.inputs, m.outputs);
    m.ports.push_back(std::move(port));
  }
  const auto h = handle_;
  node.io().Subscribe([h](const devices::IoSignal& signal) {
    if (*h) (*h)->OnIo(signal);
  });
  for (std::size_t p = 0; p < buses.size(); ++p) {
    node.stack(p).emcy().OnSent([h, p](const CanFrame& frame) {
      if (*h) (*h)->OnEmcySent(p, frame);
    });
  }
  m.SampleAll();
  m.timer.emplace(scheduler, [h] {
    if (*h) (*h)->OnTimer();
  });
  m.timer->StartAfter(std::chrono::duration_cast<Duration>(m.settings.period));
}

void NodeTelemetryWiring::Sample() {
  if (impl_->node) impl_->SampleAll();
}

void NodeTelemetryWiring::Flush() {
  for (auto& port : impl_->ports)
    if (port.publisher) port.publisher->Flush();
}

std::vector<std::string> BusNames(const NodeOptions& options) {
  std::vector<std::string> names;
  for (const auto& spec : options.buses)
    names.push_back(spec.bus);
  return names;
}

std::unique_ptr<NodeTelemetryWiring> StartNodeTelemetry(const TelemetrySettings& settings,
                                                        devices::NodeSettings& node_settings,
                                                        spdlog::logger& log) {
  if (!settings.enabled) return nullptr;
  try {
    auto wiring = std::make_unique<NodeTelemetryWiring>(settings);
    node_settings.hooks = devices::ChainHooks(std::move(node_settings.hooks), wiring->Hooks());
    log.info("telemetry: DDS domain {}{}{}", settings.dds.domain_id,
             settings.dds.config_file.empty() ? "" : ", configuration ", settings.dds.config_file);
    return wiring;
  } catch (const telemetry::DdsError& e) {
    log.error("telemetry: {}; running without telemetry", e.what());
    return nullptr;
  }
}

}  // namespace canfleet::node
