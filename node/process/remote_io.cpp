#include "node/process/remote_io.hpp"

#include <string>

namespace canfleet::node {

namespace {

wire::IoValue ToWire(const devices::IoName& name, std::string_view as_named) {
  wire::IoValue out;
  out.set_name(std::string(as_named));
  out.set_value(name.ValueText());
  out.set_unit(name.Unit());
  out.set_input(name.signal->direction() == devices::IoDirection::kInput);
  return out;
}

void Refuse(wire::NodeReply& reply, const devices::IoStatus& status) {
  reply.set_error(status.error);
  reply.set_unknown_signal(status.unknown);
  for (const auto& n : status.nearest)
    reply.add_nearest(n);
}

}  // namespace

wire::IoValue ToWire(const devices::IoSignal& signal) {
  wire::IoValue out;
  out.set_name(signal.name());
  const std::string& unit = signal.spec().unit;
  std::string text = signal.ToString();  // "2500 mV": the unit follows the number after a space
  if (signal.kind() == devices::IoKind::kNumber && !unit.empty() && text.ends_with(" " + unit))
    text.resize(text.size() - unit.size() - 1);
  out.set_value(std::move(text));
  out.set_unit(unit);
  out.set_input(signal.direction() == devices::IoDirection::kInput);
  return out;
}

wire::NodeReply AnswerNodeRequest(devices::SimulatedIo& io, const wire::NodeRequest& request) {
  wire::NodeReply reply;
  reply.set_request_id(request.request_id());
  switch (request.request_case()) {
    case wire::NodeRequest::kIoSet: {
      const wire::IoSet& set = request.io_set();
      const devices::IoStatus status = io.SetText(set.name(), set.value());
      if (!status.ok()) {
        Refuse(reply, status);
        break;
      }
      reply.set_notice(status.notice);
      *reply.add_values() = ToWire(io.Resolve(set.name()), set.name());
      break;
    }
    case wire::NodeRequest::kIoGet: {
      const std::string& name = request.io_get().name();
      if (name.empty()) {
        for (const auto& signal : io.Signals())
          *reply.add_values() = ToWire(*signal);
        break;
      }
      const devices::IoName resolved = io.Resolve(name);
      if (resolved.signal == nullptr) {
        Refuse(reply, resolved.error);
        break;
      }
      reply.set_notice(resolved.notice);
      *reply.add_values() = ToWire(resolved, name);
      break;
    }
    case wire::NodeRequest::REQUEST_NOT_SET:
      reply.set_error("empty node request (this node knows io_set and io_get)");
      break;
  }
  return reply;
}

}  // namespace canfleet::node
