#pragma once
/// @file The responses the fleet's control handlers build: an answer carrying its request's id, a
/// refusal with its one line, a "done" with its detail. Internal to the fleet.

#include <string>

#include "orchestrator/control/canfleet_control.pb.h"

namespace canfleet::fleet {

inline control::Response Reply(const control::Request& request) {
  control::Response response;
  response.set_id(request.id());
  return response;
}

/// `bad_request`: the request itself is wrong (the CLI exits 2), not the fleet unable to do it.
inline control::Response Failed(const control::Request& request, const std::string& error,
                                bool bad_request = false) {
  control::Response response = Reply(request);
  response.set_error(error);
  response.set_bad_request(bad_request);
  return response;
}

inline control::Response DoneReply(const control::Request& request, const std::string& detail) {
  control::Response response = Reply(request);
  response.mutable_done()->set_detail(detail);
  return response;
}

}  // namespace canfleet::fleet
