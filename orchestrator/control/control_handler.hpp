#pragma once
/// @file The seam between the control API's transport (ControlServer) and what answers it (the
/// fleet manager, or a fake in unit tests).

#include <cstdint>
#include <functional>
#include <memory>

#include "orchestrator/control/canfleet_control.pb.h"

namespace canfleet::control {

/// Sends responses to one client connection. Used on the io thread only; may be kept and used
/// after Handle returns (an SDO transfer answers later, a dump streams).
class Responder {
 public:
  virtual ~Responder() = default;
  /// Queues a response (its id must be set by the caller). Ignored once the connection closed.
  virtual void Send(const Response& response) = 0;
  /// True once the client has gone; streams stop then.
  virtual bool Closed() const = 0;
  /// Called once when the client goes (immediately if it already has): dumps unsubscribe here.
  virtual void OnClose(std::function<void()> handler) = 0;
  /// How many responses were sent on the connection so far (its clients count them too:
  /// ClockAdvance.responses_seen).
  virtual std::uint64_t Sent() const { return 0; }
  /// Runs `hook` after each later response on the connection (the clock's driver: an answer
  /// ends the running step). One hook; a new one replaces it.
  virtual void OnSent(std::function<void()> /*hook*/) {}
};

/// Answers requests. Every Request gets exactly one Response with its id, except DumpRequest,
/// which gets FrameBatch responses until the client closes.
class ControlHandler {
 public:
  virtual ~ControlHandler() = default;
  virtual void Handle(const Request& request, std::shared_ptr<Responder> responder) = 0;
};

}  // namespace canfleet::control
