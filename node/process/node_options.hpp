#pragma once
/// @file The command line of canfleet-node, parsed and validated before anything starts.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace canfleet::node {

/// Where one CAN port of the node is attached.
struct BusSpec {
  std::string bus;       ///< bus name on the broker ("can0"); the interface name for SocketCAN
  std::string endpoint;  ///< "tcp://host:port" or "unix:///path"; empty for SocketCAN
  bool socketcan = false;
};

struct NodeOptions {
  std::string device;                  ///< --device (empty: generic node from --eds)
  std::filesystem::path eds;           ///< --eds
  std::vector<std::uint8_t> node_ids;  ///< --node-id, one per port or one for all
  std::vector<BusSpec> buses;          ///< --bus, one per device port
  std::filesystem::path state_dir;     ///< --state-dir
  std::optional<std::uint32_t> serial_number;
  std::string name;  ///< --name (log prefix, broker port name)
  /// The fleet's token for brokers beyond loopback (--token-file, CANFLEET_TOKEN_FILE,
  /// CANFLEET_TOKEN; bus/wire/auth_token.hpp). Empty: none.
  std::string token{};
  std::vector<std::string> io;  ///< --io NAME=VALUE initial simulated inputs
  bool stdin_control = false;   ///< --stdin-control
  /// --factory-bit-rate: a port with no rate configured runs at the manual's factory rate rather
  /// than being commissioned for its bus (node/process/bit_rate_commissioning.hpp).
  bool factory_bit_rate = false;
  /// --time virtual: the node runs on time granted by the broker (lock-step virtual time,
  /// bus/broker_client/virtual_time_client.hpp); every port must be a broker connection.
  bool virtual_time = false;
  std::string log_level = "info";
};

/// Parses "can0@tcp://127.0.0.1:29600", "can1@unix:///run/canfleet.sock" or "socketcan:vcan0".
/// @throws std::invalid_argument naming the option and the problem.
BusSpec ParseBusSpec(const std::string& text);

/// The node-ID a port announces to the broker: the broker's hello takes 1..127, or 0 for "none".
/// An unconfigured LSS slave (--node-id 255, CiA 305 §8.2) has none until a master assigns one.
constexpr std::uint32_t BrokerHelloNodeId(std::uint8_t node_id) {
  return node_id >= 1 && node_id <= 127 ? node_id : 0;
}

}  // namespace canfleet::node
