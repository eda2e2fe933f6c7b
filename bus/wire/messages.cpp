#include "bus/wire/messages.hpp"

#include <utility>

namespace canfleet::wire {

const char* ToString(MessageType type) {
  switch (type) {
    case MessageType::kHello:
      return "Hello";
    case MessageType::kHelloReply:
      return "HelloReply";
    case MessageType::kFrames:
      return "FrameBatch";
    case MessageType::kTxConfirm:
      return "TxConfirm";
    case MessageType::kControllerEvent:
      return "ControllerEvent";
    case MessageType::kPing:
      return "Ping";
    case MessageType::kPong:
      return "Pong";
    case MessageType::kError:
      return "Error";
    case MessageType::kNodeRequest:
      return "NodeRequest";
    case MessageType::kNodeReply:
      return "NodeReply";
    case MessageType::kBitRate:
      return "BitRate";
    case MessageType::kTimeGrant:
      return "TimeGrant";
    case MessageType::kTimeReached:
      return "TimeReached";
    case MessageType::kAcceptance:
      return "Acceptance";
  }
  return "unknown";
}

Hello MakeHello(std::string bus, std::string node_name, std::uint32_t node_id, Role role) {
  Hello hello;
  hello.set_protocol_version(kProtocolVersion);
  hello.set_bus(std::move(bus));
  hello.set_node_name(std::move(node_name));
  hello.set_node_id(node_id);
  hello.set_role(role);
  return hello;
}

ControllerState ToWire(canfleet::ControllerState state) {
  switch (state) {
    case canfleet::ControllerState::kErrorActive:
      return CONTROLLER_STATE_ERROR_ACTIVE;
    case canfleet::ControllerState::kErrorPassive:
      return CONTROLLER_STATE_ERROR_PASSIVE;
    case canfleet::ControllerState::kBusOff:
      return CONTROLLER_STATE_BUS_OFF;
  }
  return CONTROLLER_STATE_ERROR_ACTIVE;
}

std::optional<canfleet::ControllerState> FromWire(int state) {
  switch (state) {
    case CONTROLLER_STATE_ERROR_ACTIVE:
      return canfleet::ControllerState::kErrorActive;
    case CONTROLLER_STATE_ERROR_PASSIVE:
      return canfleet::ControllerState::kErrorPassive;
    case CONTROLLER_STATE_BUS_OFF:
      return canfleet::ControllerState::kBusOff;
    default:
      return std::nullopt;
  }
}

}  // namespace canfleet::wire
