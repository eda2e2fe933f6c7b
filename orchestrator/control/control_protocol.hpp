#pragma once
/// @file The control API's framing and endpoint syntax, shared by ControlServer and ControlClient
/// (canfleet_control.proto): each message preceded by its length as a base-128 varint
/// (protobuf's writeDelimitedTo framing), at most kMaxControlMessage bytes.

#include <google/protobuf/message_lite.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bus/wire/endpoint.hpp"

namespace canfleet::control {

/// The control API's conventional TCP port and default endpoint (loopback only).
inline constexpr std::uint16_t kDefaultControlPort = 29700;
inline constexpr std::string_view kDefaultControlEndpoint = "tcp://127.0.0.1:29700";

/// Largest message (without its length prefix) either side accepts: 1 MiB.
inline constexpr std::size_t kMaxControlMessage = std::size_t{1} << 20;

/// Parses a control endpoint, `tcp://HOST:PORT` (IPv6 in brackets; port 0 = any free port when
/// listening). Throws std::invalid_argument naming what is wrong ("the control API speaks TCP
/// only" for a unix:// endpoint).
wire::Endpoint ParseControlEndpoint(std::string_view text);

/// Appends `message` with its varint length prefix to `out`. Returns false (and appends nothing)
/// when the message exceeds `max_size` bytes.
bool AppendDelimited(const google::protobuf::MessageLite& message, std::string& out,
                     std::size_t max_size = kMaxControlMessage);

/// Splits a received byte stream into messages. Copes with any split into reads; every malformed
/// input (overlong varint, length over the limit, a body that does not parse) is an error, after
/// which the reader stays failed.
class DelimitedReader {
 public:
  enum class Result : std::uint8_t { kNeedMore, kMessage, kError };

  explicit DelimitedReader(std::size_t max_size = kMaxControlMessage) : max_size_(max_size) {}

  /// Adds received bytes.
  void Append(std::span<const std::uint8_t> bytes);
  void Append(const void* data, std::size_t size) {
    Append(std::span<const std::uint8_t>(static_cast<const std::uint8_t*>(data), size));
  }

  /// Parses the next complete message into `out` (cleared first).
  Result Next(google::protobuf::MessageLite& out);

  bool Failed() const { return failed_; }
  /// Why the stream was rejected ("message of 2000000 bytes exceeds the limit of 1048576").
  const std::string& Error() const { return error_; }
  /// Bytes received and not yet returned as a message.
  std::size_t Buffered() const { return buffer_.size() - begin_; }

 private:
  Result Fail(std::string reason);

  std::size_t max_size_;
  std::vector<std::uint8_t> buffer_;
  std::size_t begin_ = 0;  ///< first byte not yet consumed
  bool failed_ = false;
  std::string error_;
};

}  // namespace canfleet::control
