#pragma once
// Helpers shared by the wire codec tests.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "bus/can_frame.hpp"
#include "bus/wire/message_writer.hpp"
#include "bus/wire/stream_decoder.hpp"
#include "tests/support/bus_probe.hpp"
#include "tests/support/wire_text.hpp"

namespace canfleet::wire::test {

using Bytes = std::vector<std::uint8_t>;

inline Bytes ToBytes(std::span<const std::uint8_t> s) {
  return Bytes(s.begin(), s.end());
}
inline Bytes ToBytes(const std::string& s) {
  return Bytes(s.begin(), s.end());
}

/// A decoded message reduced to comparable text, e.g. "Frames 123#DEADBEEF@5 7FF#R@9".
inline std::string Describe(const Message& m) {
  std::string out = ToString(m.type);
  switch (m.type) {
    case MessageType::kFrames:
    case MessageType::kTxConfirm:
      for (std::size_t i = 0; i < m.frames.size(); ++i) {
        const StampedFrame f = m.frames[i];
        out += " " + ToCandump(f.frame) + "@" + std::to_string(f.time.count());
        if (f.frame.error()) out += "!";
      }
      break;
    case MessageType::kControllerEvent:
      out += std::string(" ") + canfleet::ToString(m.controller.state) + " " +
             std::to_string(m.controller.tec) + " " + std::to_string(m.controller.rec);
      break;
    case MessageType::kHello:
      out += " " + canfleet::test::WireText(m.envelope.hello());
      break;
    case MessageType::kHelloReply:
      out += " " + canfleet::test::WireText(m.envelope.hello_reply());
      break;
    case MessageType::kPing:
      out += " " + std::to_string(m.envelope.ping().nonce());
      break;
    case MessageType::kPong:
      out += " " + std::to_string(m.envelope.pong().nonce());
      break;
    case MessageType::kError:
      out += " " + m.envelope.error().reason();
      break;
    case MessageType::kNodeRequest:
      out += " " + canfleet::test::WireText(m.envelope.node_request());
      break;
    case MessageType::kNodeReply:
      out += " " + canfleet::test::WireText(m.envelope.node_reply());
      break;
    case MessageType::kBitRate:
      out += " " + std::to_string(m.envelope.bit_rate().bitrate());
      break;
    case MessageType::kTimeGrant:
      out += " " + std::to_string(m.envelope.time_grant().now_ns()) + ".." +
             std::to_string(m.envelope.time_grant().until_ns());
      for (const std::uint64_t a : m.envelope.time_grant().attachments())
        out += " #" + std::to_string(a);
      break;
    case MessageType::kAcceptance:
      out += m.envelope.acceptance().all()
                 ? " all"
                 : " " + std::to_string(m.envelope.acceptance().ids_size()) + " ids";
      break;
    case MessageType::kTimeReached:
      out += " " + std::to_string(m.envelope.time_reached().time_ns()) +
             (m.envelope.time_reached().has_deadline()
                  ? " next " + std::to_string(m.envelope.time_reached().next_deadline_ns())
                  : std::string(" idle"));
      break;
  }
  return out;
}

struct DecodeOutcome {
  std::vector<std::string> messages;
  bool failed = false;
  std::string error;
};

/// Feeds `bytes` in chunks of `chunk` bytes (0 = all at once), decoding after each chunk.
inline DecodeOutcome DecodeAll(std::span<const std::uint8_t> bytes, std::size_t chunk = 0,
                               std::size_t max_message = kMaxMessageSize) {
  StreamDecoder decoder(max_message);
  Message message;
  DecodeOutcome out;
  if (chunk == 0) chunk = bytes.size() == 0 ? 1 : bytes.size();
  for (std::size_t at = 0; at < bytes.size() && !out.failed; at += chunk) {
    decoder.Feed(bytes.subspan(at, std::min(chunk, bytes.size() - at)));
    for (;;) {
      const auto result = decoder.Next(message);
      if (result == StreamDecoder::Result::kNeedMore) break;
      if (result == StreamDecoder::Result::kError) {
        out.failed = true;
        out.error = decoder.Error();
        break;
      }
      out.messages.push_back(Describe(message));
    }
  }
  return out;
}

using canfleet::test::Frame;

}  // namespace canfleet::wire::test
