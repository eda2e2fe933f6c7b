#pragma once
/// @file Where a broker listens and a node connects: `tcp://host:port` or `unix:///path`.

#include <cstdint>
#include <string>
#include <string_view>

namespace canfleet::wire {

/// The broker's conventional TCP port.
inline constexpr std::uint16_t kDefaultBrokerPort = 29600;

struct Endpoint {
  enum class Kind : std::uint8_t { kTcp, kUnix };

  Kind kind = Kind::kTcp;
  std::string host;        ///< kTcp: a name or an address, IPv6 without brackets ("::1")
  std::uint16_t port = 0;  ///< kTcp: 0 = any free port (listening only)
  std::string path;        ///< kUnix: filesystem path of the socket

  /// Parses `tcp://127.0.0.1:29600`, `tcp://[::1]:29600`, `tcp://localhost:29600`,
  /// `unix:///run/canfleet/broker.sock` (or a relative `unix://broker.sock`). Throws
  /// std::invalid_argument naming what is wrong.
  static Endpoint Parse(std::string_view text);

  /// The canonical text (Parse(ToString()) == *this).
  std::string ToString() const;

  /// True for a TCP endpoint on a loopback address (127.0.0.0/8, ::1, "localhost").
  bool IsLoopback() const;

  friend bool operator==(const Endpoint&, const Endpoint&) = default;
};

}  // namespace canfleet::wire
