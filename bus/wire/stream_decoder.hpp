#pragma once
/// @file Splits a byte stream into messages: varint length prefix, then one Envelope
/// (canfleet_wire.proto). Copes with any split of the stream into reads (a message across many
/// reads, many messages in one read) and turns every malformed input into an error, never a crash.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "bus/wire/byte_buffer.hpp"
#include "bus/wire/messages.hpp"

namespace canfleet::wire {

/// Usage on a socket: read into WritableSpace(), Commit() what was read, then call Next() until it
/// says kNeedMore (or kError: close the connection, Error() says why).
///
/// Frames batches in the canonical encoding (what MessageWriter and protobuf write) are decoded
/// in place: no copy, no allocation. Anything else goes through the generated protobuf parser.
/// After an error the decoder stays failed.
class StreamDecoder {
 public:
  enum class Result : std::uint8_t { kNeedMore, kMessage, kError };

  /// `max_message`: largest Envelope accepted (without its length prefix).
  explicit StreamDecoder(std::size_t max_message = kMaxMessageSize);

  /// Room for at least `min` more bytes at the end of the buffered data (more when a partial
  /// message needs it). Invalidates the frames of messages returned earlier.
  std::span<std::uint8_t> WritableSpace(std::size_t min = 64 * 1024);
  /// Marks `n` bytes of the last WritableSpace() as received.
  void Commit(std::size_t n);
  /// Copies bytes in (tests, fuzzing); same as WritableSpace + memcpy + Commit.
  void Feed(std::span<const std::uint8_t> bytes);

  /// Decodes the next complete message into `out`.
  Result Next(Message& out);

  bool Failed() const { return failed_; }
  /// Why the stream was rejected ("message of 2097152 bytes exceeds the limit of 1048576").
  const std::string& Error() const { return error_; }
  /// Bytes received but not yet decoded.
  std::size_t Buffered() const { return end_ - begin_; }

 private:
  Result Fail(std::string reason);
  bool DecodeBody(std::span<const std::uint8_t> body, Message& out);
  bool DecodeBatchFast(std::span<const std::uint8_t> batch, MessageType type, Message& out);
  bool DecodeEnvelope(std::span<const std::uint8_t> body, Message& out);

  std::size_t max_message_;
  ByteBuffer buffer_;
  std::size_t begin_ = 0;   ///< first byte not yet decoded
  std::size_t end_ = 0;     ///< end of received bytes
  std::size_t wanted_ = 0;  ///< size of the partial message at begin_ (prefix included), when known
  bool failed_ = false;
  std::string error_;
};

}  // namespace canfleet::wire
