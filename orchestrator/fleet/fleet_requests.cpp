// The control API's answers (Fleet::Handle) and the requests that travel over the bus or the
// node connection before they can be answered (SDO, simulated I/O).
#include <spdlog/spdlog.h>

#include <asio/post.hpp>

#include "orchestrator/control/sdo_value.hpp"
#include "orchestrator/fleet/control_replies.hpp"
#include "orchestrator/fleet/fleet.hpp"
#include "vocabulary/nearest_names.hpp"

namespace canfleet::fleet {

namespace {

/// Dump subscriptions stay alive while their client is connected.
struct DumpHolder {
  std::unique_ptr<DumpSubscription> subscription;
};

}  // namespace

void Fleet::Handle(const control::Request& request, std::shared_ptr<control::Responder> responder) {
  using R = control::Request;
  try {
    switch (request.body_case()) {
      case R::kStatus: {
        auto response = Reply(request);
        *response.mutable_status() = Status();
        responder->Send(response);
        return;
      }
      case R::kFaultInject: {
        auto response = Reply(request);
        *response.mutable_fault_injected() = faults_->Inject(request.fault_inject());
        responder->Send(response);
        return;
      }
      case R::kFaultClear: {
        const auto n = faults_->Clear(request.fault_clear());
        responder->Send(DoneReply(request, "cleared " + std::to_string(n) + (n == 1 ? " fault" : " faults")));
        return;
      }
      case R::kFaultList: {
        auto response = Reply(request);
        for (auto& status : faults_->List(request.fault_list().include_ended()))
          *response.mutable_faults()->add_faults() = std::move(status);
        responder->Send(response);
        return;
      }
      case R::kIoSet: {
        NodeOrThrow(request.io_set().node());
        wire::NodeRequest node_request;
        node_request.mutable_io_set()->set_name(request.io_set().name());
        node_request.mutable_io_set()->set_value(request.io_set().value());
        IoRequest(request.io_set().node(), node_request, [request, responder](const IoAnswer& answer) {
          if (!answer.error.empty())
            return responder->Send(Failed(request, answer.error, answer.bad_request));
          auto response = DoneReply(request, request.io_set().name() + " = " + request.io_set().value());
          response.set_notice(answer.notice);
          responder->Send(response);
        });
        return;
      }
      case R::kIoGet: {
        NodeOrThrow(request.io_get().node());
        wire::NodeRequest node_request;
        node_request.mutable_io_get()->set_name(request.io_get().name());
        IoRequest(request.io_get().node(), node_request, [request, responder](const IoAnswer& answer) {
          if (!answer.error.empty())
            return responder->Send(Failed(request, answer.error, answer.bad_request));
          auto response = Reply(request);
          *response.mutable_io() = answer.values;
          response.set_notice(answer.notice);
          responder->Send(response);
        });
        return;
      }
      case R::kSdoRead:
        SdoRead(request, responder);
        return;
      case R::kSdoWrite:
        SdoWrite(request.sdo_write(), [request, responder](const std::string& error) {
          responder->Send(error.empty() ? DoneReply(request, "written") : Failed(request, error));
        });
        return;
      case R::kNmt:
        responder->Send(DoneReply(request, Nmt(request.nmt())));
        return;
      case R::kDump:
        StartDump(request, responder);
        return;
      case R::kCaptureStart: {
        auto response = Reply(request);
        *response.mutable_capture() = captures_.Start(request.capture_start());
        spdlog::info("capture {} of {} started: {}", response.capture().capture_id(),
                     request.capture_start().bus(), response.capture().path());
        responder->Send(response);
        return;
      }
      case R::kCaptureStop: {
        const auto line = captures_.Stop(request.capture_stop().capture_id());
        spdlog::info("{}", line);
        responder->Send(DoneReply(request, line));
        return;
      }
      case R::kClockAdvance:
        AdvanceClock(request, responder);
        return;
      case R::kExpect:
        StartExpect(request, responder);
        return;
      case R::kShutdown:
        responder->Send(DoneReply(request, "shutting down"));
        if (on_shutdown_request_) asio::post(io_, on_shutdown_request_);
        return;
      default:
        responder->Send(Failed(request, "empty or unknown request"));
        return;
    }
  } catch (const FaultError& e) {
    responder->Send(Failed(request, e.what(), e.bad_request()));
  } catch (const std::invalid_argument& e) {  // an unknown node, bus or capture; a value out of range
    responder->Send(Failed(request, e.what(), true));
  } catch (const std::exception& e) {
    responder->Send(Failed(request, e.what()));
  }
}

control::Status Fleet::Status() const {
  control::Status status;
  status.set_topology(options_.topology.name());
  status.set_uptime_s(Uptime());
  if (options_.conductor != nullptr) {
    status.set_virtual_time(true);
    status.set_speed_factor(options_.conductor->Factor());
    status.set_speed(options_.conductor->Speed());
    status.set_driven(options_.conductor->Driven());
    status.set_now_ns(options_.conductor->Now().time_since_epoch().count());
  }
  std::map<std::pair<std::string, std::string>, broker::PortStats> ports;  // (bus, name)
  std::map<std::string, std::uint32_t> bus_rates;
  for (const auto& bus : broker_.Buses()) {
    const auto stats = broker_.Stats(bus, 0);
    auto* out = status.add_buses();
    out->set_name(bus);
    out->set_bitrate(stats.bitrate);
    out->set_paced(stats.paced);
    out->set_ports(static_cast<std::uint32_t>(stats.ports));
    out->set_load_percent(stats.load_percent);
    out->set_frames_per_s(stats.frames_per_s);
    out->set_error_frames_per_s(stats.error_frames_per_s);
    out->set_frames(stats.frames);
    out->set_error_frames(stats.error_frames);
    bus_rates[bus] = stats.bitrate;
    for (auto& port : broker_.Ports(bus))
      ports[{bus, port.name}] = port;  // the newest attachment of a name wins
  }
  for (const auto& node : nodes_) {
    auto* out = status.add_nodes();
    out->set_name(node.name());
    out->set_device(node.device_label);
    for (std::size_t p = 0; p < node.buses.size(); ++p) {
      out->add_node_ids(node.node_ids[p]);
      out->add_buses(node.buses[p]);
    }
    if (node.external()) {
      out->set_process("external");
    } else {
      const auto view = supervisor_.View(node.name());
      out->set_process(view.state);
      out->set_detail(view.detail);
      out->set_pid(view.pid);
      out->set_restarts(view.restarts);
    }
    bool attached = true;
    for (const auto& bus : node.buses)
      attached = attached && ports.count({bus, node.name()}) != 0;
    out->set_attached(attached);

    // Each port as the master sees it on its bus; the node's own fields repeat port 1's.
    for (std::size_t p = 0; p < node.buses.size(); ++p) {
      const std::string& bus = node.buses[p];
      auto* port = out->add_ports();
      port->set_can("CAN" + std::to_string(out->ports_size()));
      port->set_bus(bus);
      port->set_node_id(node.node_ids[p]);
      if (auto it = ports.find({bus, node.name()}); it != ports.end()) {
        const auto& c = it->second.controller;
        port->set_controller(c.state == ControllerState::kBusOff         ? "bus-off"
                             : c.state == ControllerState::kErrorPassive ? "error-passive"
                                                                         : "error-active");
        port->set_tec(c.tec);
        port->set_rec(c.rec);
        if (it->second.bitrate != bus_rates[bus]) port->set_bitrate(it->second.bitrate);
      }
      const NodeLiveState* live = tracker_.Find(bus, node.node_ids[p]);
      port->set_booted(live && live->booted);
      port->set_nmt_state(NmtStateName(live ? live->nmt_state : std::nullopt));
      port->set_nmt_stale(live && live->Stale(scheduler_.Now()));
      port->set_heartbeat_age_s(
          live && live->last_heartbeat
              ? std::chrono::duration<double>(scheduler_.Now() - *live->last_heartbeat).count()
              : -1.0);
      if (live && live->last_emcy) {
        auto* emcy = port->mutable_last_emcy();
        emcy->set_code(live->last_emcy->code);
        emcy->set_register_(live->last_emcy->error_register);
        emcy->set_manufacturer(
            std::string(live->last_emcy->manufacturer.begin(), live->last_emcy->manufacturer.end()));
        emcy->set_time_s(std::chrono::duration<double>(live->last_emcy->time - origin_).count());
        port->set_emcy_count(live->emcy_count);
      }
    }
    const control::PortStatus& first = out->ports(0);
    out->set_controller(first.controller());
    out->set_tec(first.tec());
    out->set_rec(first.rec());
    out->set_booted(first.booted());
    out->set_nmt_state(first.nmt_state());
    out->set_nmt_stale(first.nmt_stale());
    out->set_heartbeat_age_s(first.heartbeat_age_s());
    if (first.has_last_emcy()) *out->mutable_last_emcy() = first.last_emcy();
    out->set_emcy_count(first.emcy_count());
    if (out->detail().empty()) {
      auto rt = runtime_.find({node.name(), 0});
      if (rt != runtime_.end()) out->set_detail(rt->second.configuration);
    }
  }
  for (auto& fault : faults_->List(false))
    *status.add_faults() = std::move(fault);
  return status;
}

void Fleet::SdoRead(const control::Request& request, std::shared_ptr<control::Responder> responder) {
  const auto& read = request.sdo_read();
  const FleetNode& node = NodeOrThrow(read.node());
  if (read.port() >= node.buses.size())
    throw std::invalid_argument("node '" + node.name() + "' has no CAN" + std::to_string(read.port() + 1) +
                                " (it has " + std::to_string(node.buses.size()) + " CAN port(s))");
  if (read.index() > 0xFFFF || read.subindex() > 0xFF)
    throw std::invalid_argument("index 0..FFFFh, sub-index 0..FFh");
  if (!read.type().empty()) control::RequireSdoType(read.type());  // refuse an unknown type before the bus
  const auto& bus = node.buses[read.port()];
  sdo_.at(bus)->Read(
      node.node_ids[read.port()], static_cast<std::uint16_t>(read.index()),
      static_cast<std::uint8_t>(read.subindex()), read.block(),
      [request, responder](canopen::SdoAbort abort, canopen::Bytes data) {
        if (abort != canopen::SdoAbort::kNone) return responder->Send(Failed(request, DescribeAbort(abort)));
        auto response = Reply(request);
        auto* out = response.mutable_sdo();
        out->set_data(std::string(data.begin(), data.end()));
        const auto& type = request.sdo_read().type();
        try {
          out->set_text(type.empty() ? control::HexBytes(data) : control::FormatSdoValue(type, data));
        } catch (const std::exception& e) {
          // The bytes arrived; say why they do not read as the asked type.
          out->set_text(control::HexBytes(data) + " (" + e.what() + ")");
        }
        responder->Send(response);
      });
}

void Fleet::SdoWrite(const control::SdoWrite& write, std::function<void(std::string error)> done) {
  const FleetNode& node = NodeOrThrow(write.node());
  if (write.port() >= node.buses.size())
    throw std::invalid_argument("node '" + node.name() + "' has no CAN" + std::to_string(write.port() + 1) +
                                " (it has " + std::to_string(node.buses.size()) + " CAN port(s))");
  if (write.index() > 0xFFFF || write.subindex() > 0xFF)
    throw std::invalid_argument("index 0..FFFFh, sub-index 0..FFh");
  auto data = control::EncodeSdoValue(write.type(), write.value());
  const auto& bus = node.buses[write.port()];
  sdo_.at(bus)->Write(node.node_ids[write.port()], static_cast<std::uint16_t>(write.index()),
                      static_cast<std::uint8_t>(write.subindex()), std::move(data), write.block(),
                      [done](canopen::SdoAbort abort) {
                        done(abort == canopen::SdoAbort::kNone ? std::string() : DescribeAbort(abort));
                      });
}

void Fleet::IoRequest(const std::string& node_name, wire::NodeRequest request,
                      std::function<void(const IoAnswer&)> done) {
  const FleetNode& node = NodeOrThrow(node_name);
  const std::string asked = request.has_io_set() ? request.io_set().name() : request.io_get().name();
  server_.RequestNode(
      node.buses.front(), node.name(), std::move(request),
      [done, node_name, asked](std::optional<wire::NodeReply> reply) {
        IoAnswer answer;
        answer.values.set_node(node_name);
        if (!reply) {
          answer.error = "node '" + node_name + "' did not answer (is it attached?)";
          return done(answer);
        }
        if (!reply->error().empty()) {
          // What the node refuses is the request's fault: a name, a type, a range.
          answer.bad_request = true;
          answer.error = reply->error();
          if (reply->unknown_signal()) {
            answer.error = "no signal " + asked + " on " + node_name;
            if (reply->nearest_size() > 0)
              answer.error += "; nearest: " + JoinNames({reply->nearest().begin(), reply->nearest().end()});
            answer.error += "; all: canfleet io get " + node_name;
          }
          return done(answer);
        }
        answer.notice = reply->notice();
        for (const auto& v : reply->values()) {
          auto* out = answer.values.add_values();
          out->set_name(v.name());
          out->set_value(v.value());
          out->set_unit(v.unit());
          out->set_input(v.input());
        }
        done(answer);
      });
}

void Fleet::StartDump(const control::Request& request, std::shared_ptr<control::Responder> responder) {
  std::vector<std::string> buses;
  if (request.dump().bus().empty()) {
    buses = broker_.Buses();
  } else {
    buses.push_back(request.dump().bus());
    broker_.Stats(request.dump().bus(), 0);  // throws for an unknown bus
  }
  auto holder = std::make_shared<DumpHolder>();
  holder->subscription = std::make_unique<DumpSubscription>(broker_, buses, request.dump(), request.id(),
                                                            responder, wall_origin_);
  // The subscription lives as long as the client: the responder keeps this closure.
  responder->OnClose([holder] { holder->subscription.reset(); });
}

}  // namespace canfleet::fleet
