#include "node/process/remote_io.hpp"

#include <string>

namespace canfleet::node {

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
        reply.set_error(status.error);
        break;
      }
      *reply.add_values() = ToWire(*io.Find(set.name()));
      break;
    }
    case wire::NodeRequest::kIoGet: {
      const std::string& name = request.io_get().name();
      if (name.empty()) {
        for (const auto& signal : io.Signals())
          *reply.add_values() = ToWire(*signal);
        break;
      }
      const devices::IoSignal* signal = io.Find(name);
      if (signal == nullptr) {
        reply.set_error("unknown signal \"" + name + "\"");
        break;
      }
      *reply.add_values() = ToWire(*signal);
      break;
    }
    case wire::NodeRequest::REQUEST_NOT_SET:
      reply.set_error("empty node request (this node knows io_set and io_get)");
      break;
  }
  return reply;
}

}  // namespace canfleet::node
