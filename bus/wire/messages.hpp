#pragma once
/// @file The node <-> broker protocol: constants of the framing and one decoded message. The
/// schema is canfleet_wire.proto; its generated types (canfleet::wire::Hello, HelloReply, ...) are
/// used as they are for the rare control messages, while frames travel as packed records
/// (frame_record.hpp) that are encoded and decoded by hand.
///
/// Inside namespace canfleet::wire, `ControllerEvent` names the protobuf message; the bus's value
/// type is `canfleet::ControllerEvent`.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "bus/bus_port.hpp"
#include "bus/wire/canfleet_wire.pb.h"
#include "bus/wire/frame_record.hpp"

namespace canfleet::wire {

/// Bumped on any incompatible change of canfleet_wire.proto or of the record layout. A Hello with
/// another version is refused with a reason naming both.
/// 2: NodeRequest / NodeReply.
/// 3: Hello.bitrate and BitRate (the node's controller bit rate).
/// 4: virtual time (Hello.virtual_time, TimeGrant, TimeReached, Acceptance).
inline constexpr std::uint32_t kProtocolVersion = 4;

/// Largest Envelope (without its length prefix). Longer = protocol error.
inline constexpr std::size_t kMaxMessageSize = std::size_t{1} << 20;

/// The writer splits batches larger than this into several messages (96 KiB each).
inline constexpr std::size_t kMaxFramesPerMessage = 4096;
static_assert(kMaxFramesPerMessage * kFrameRecordSize + 16 <= kMaxMessageSize);

/// Longest bus or node name a Hello may carry.
inline constexpr std::size_t kMaxNameLength = 128;

enum class MessageType : std::uint8_t {
  kHello,
  kHelloReply,
  kFrames,     ///< frames to send (node -> broker) or received (broker -> node)
  kTxConfirm,  ///< own frames acknowledged on the bus (broker -> node)
  kControllerEvent,
  kPing,
  kPong,
  kError,        ///< the peer is about to close; envelope.error().reason() says why
  kNodeRequest,  ///< broker -> node: envelope.node_request()
  kNodeReply,    ///< node -> broker: envelope.node_reply()
  kBitRate,      ///< node -> broker: envelope.bit_rate()
  kTimeGrant,    ///< broker -> node (virtual time): envelope.time_grant()
  kTimeReached,  ///< node -> broker (virtual time): envelope.time_reached()
  kAcceptance,   ///< node -> broker (virtual time): envelope.acceptance()
};

const char* ToString(MessageType type);

/// One decoded message. Reusing one Message for a whole stream reuses its storage.
struct Message {
  MessageType type = MessageType::kError;
  /// kFrames, kTxConfirm: the records, pointing into the decoder's buffer (valid until the decoder
  /// is written to again).
  FrameRecords frames;
  /// kControllerEvent, converted and range-checked.
  canfleet::ControllerEvent controller;
  /// kHello, kHelloReply, kPing, kPong, kError, kNodeRequest, kNodeReply, kBitRate, kTimeGrant,
  /// kTimeReached: the parsed Envelope
  /// (envelope.hello(), ...).
  Envelope envelope;
};

/// A Hello for this library's protocol version.
Hello MakeHello(std::string bus, std::string node_name, std::uint32_t node_id = 0, Role role = ROLE_NODE);

/// Converts between the bus's controller state and the schema's (protobuf enums are open, so an
/// unknown value yields nullopt).
ControllerState ToWire(canfleet::ControllerState state);
std::optional<canfleet::ControllerState> FromWire(int state);

}  // namespace canfleet::wire
