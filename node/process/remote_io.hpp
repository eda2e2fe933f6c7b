#pragma once
/// @file Remote I/O: the node's answers to the broker's NodeRequests (bus/wire/canfleet_wire.proto),
/// so the orchestrator sets and reads a node's simulated I/O (design decision 5) over the bus
/// connection it already has, wherever the node runs (same host, container, other host).
///
///   io_set {name: "IN1.voltage_mV", value: "3000"} → reply with the signal as now set, or error
///                                  "no signal IN9.voltage_mV; nearest: IN1.voltage_mV, ..." (unknown_signal,
///                                  nearest)
///   io_get {name: "IN1.voltage_mV"}                 → that signal: value "3000", unit "mV", input
///   io_get {}                                       → every signal, in declaration order
/// An old name works, read and set in its old unit, and the reply's notice says it is deprecated;
/// a set of a quantity the pin's configuration does not read is done, with a notice saying so.

#include "bus/wire/canfleet_wire.pb.h"
#include "node/devices/simulated_io.hpp"

namespace canfleet::node {

/// Executes `request` on `io` and returns the reply (request_id copied). Errors are data: the
/// reply's `error` says, in one line, what was wrong (SimulatedIo's own messages for a bad name,
/// direction, type or range); nothing is changed then. `notice`: a done request's warning.
wire::NodeReply AnswerNodeRequest(devices::SimulatedIo& io, const wire::NodeRequest& request);

/// One signal as the wire carries it: the value without its unit ("3000"), the unit apart ("mV").
wire::IoValue ToWire(const devices::IoSignal& signal);

}  // namespace canfleet::node
