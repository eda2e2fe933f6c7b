#pragma once
/// @file The bit rate a node's port starts at on the broker (orchestrator/broker/README.md "Bit
/// rate": a port at another rate than its bus's exchanges no frames with it).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "bus/bus_port.hpp"
#include "node/devices/device_node.hpp"

namespace canfleet::node {

/// What CommissionBitRate decided for one port.
struct Commissioning {
  /// The index the stack adopted (nullopt: it kept its own).
  std::optional<std::uint8_t> adopted;
  /// One line for the node's log ("" when there is nothing to say).
  std::string message;
};

/// At the first connection, before power-on, for a broker port whose controller states no rate yet
/// (`stated` 0: neither an LSS configuration stored by CiA 305 "store configuration" nor anything
/// else set one): the node is taken as commissioned for the bus it is plugged into, as an installer
/// would have configured it. The stack adopts the CiA 305 table-0 index of `bus_bitrate` (so that
/// LSS and the device's bit-rate object report and store the rate it runs at), and the port states
/// that rate from now on. A bus rate without a table-0 index (e.g. 83.3 kbit/s) leaves both alone:
/// the port runs at the bus's rate unstated. `factory_index`: the stack's index before (the
/// manual's factory rate), for the message.
Commissioning CommissionFor(std::uint32_t stated, std::uint32_t bus_bitrate, std::uint8_t factory_index);

/// Applies CommissionFor to port `p` of `node` when `port` is a broker client port; logs the
/// result. Other ports (SocketCAN) are left alone.
void CommissionBitRate(devices::DeviceNode& node, std::size_t p, BusPort& port,
                       const std::function<void(const std::string&)>& log);

/// --factory-bit-rate: for a broker port whose controller states no rate yet, states the stack's
/// own rate (its stored LSS configuration or the manual's factory rate), so a factory-new device on
/// a bus at another rate sees error frames and no traffic until a master sets its rate by LSS or
/// its bit-rate object. Other ports (SocketCAN) are left alone.
void KeepFactoryBitRate(devices::DeviceNode& node, std::size_t p, BusPort& port,
                        const std::function<void(const std::string&)>& log);

}  // namespace canfleet::node
