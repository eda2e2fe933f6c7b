#include "web/action_forwarder.hpp"

#include <google/protobuf/util/json_util.h>

#include "orchestrator/control/control_client.hpp"
#include "tools/telemetry/event_format.hpp"

namespace canfleet::web {

ForwardedAction ForwardAction(const std::string& control_endpoint, const control::Request& request) {
  try {
    control::ControlClient client(control_endpoint);
    const control::Response response = client.Call(request);
    std::string json;
    google::protobuf::util::JsonPrintOptions print;
    print.preserve_proto_field_names = true;
    (void)google::protobuf::util::MessageToJsonString(response, &json, print);
    return {true, std::string("{\"ok\":") + (response.error().empty() ? "true" : "false") +
                      ",\"error\":" + tools::JsonString(response.error()) + ",\"response\":" + json + "}"};
  } catch (const std::exception& e) {
    return {false, "{\"ok\":false,\"error\":" + tools::JsonString(e.what()) + "}"};
  }
}

}  // namespace canfleet::web
