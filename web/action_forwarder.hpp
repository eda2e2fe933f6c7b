#pragma once
/// @file The page's actions, sent on to the orchestrator's control API. Its own file: the control
/// client is built on standalone Asio, the web server on Boost.Asio, and the two cannot share a
/// translation unit (their execution traits collide).

#include <string>

#include "orchestrator/control/canfleet_control.pb.h"

namespace canfleet::web {

struct ForwardedAction {
  bool reached = false;  ///< false: the orchestrator could not be reached (`json` says why)
  std::string json;      ///< {"ok", "error", "response"} or {"ok": false, "error"}
};

/// Sends `request` to the control API at `control` and waits for its answer (blocking).
ForwardedAction ForwardAction(const std::string& control, const control::Request& request);

}  // namespace canfleet::web
