#include "bus/wire/endpoint.hpp"

#include <charconv>
#include <stdexcept>

namespace canfleet::wire {

namespace {

/// sockaddr_un::sun_path holds 108 bytes including the terminating NUL (unix(7)).
constexpr std::size_t kMaxUnixPath = 107;

[[noreturn]] void Invalid(std::string_view text, std::string_view why) {
  throw std::invalid_argument("endpoint \"" + std::string(text) + "\": " + std::string(why) +
                              " (expected tcp://host:port or unix:///path)");
}

}  // namespace

Endpoint Endpoint::Parse(std::string_view text) {
  constexpr std::string_view kTcp = "tcp://";
  constexpr std::string_view kUnix = "unix://";
  Endpoint ep;
  if (text.starts_with(kUnix)) {
    ep.kind = Kind::kUnix;
    ep.path = std::string(text.substr(kUnix.size()));
    if (ep.path.empty()) Invalid(text, "empty socket path");
    if (ep.path.size() > kMaxUnixPath) Invalid(text, "socket path longer than 107 bytes");
    if (ep.path.find('\0') != std::string::npos) Invalid(text, "NUL in socket path");
    return ep;
  }
  if (!text.starts_with(kTcp)) Invalid(text, "unknown scheme");
  std::string_view rest = text.substr(kTcp.size());
  std::string_view host;
  std::string_view port;
  if (rest.starts_with('[')) {
    const auto close = rest.find(']');
    if (close == std::string_view::npos) Invalid(text, "unterminated [IPv6 address]");
    host = rest.substr(1, close - 1);
    rest = rest.substr(close + 1);
    if (!rest.starts_with(':')) Invalid(text, "missing :port");
    port = rest.substr(1);
  } else {
    const auto colon = rest.rfind(':');
    if (colon == std::string_view::npos) Invalid(text, "missing :port");
    host = rest.substr(0, colon);
    port = rest.substr(colon + 1);
    if (host.find(':') != std::string_view::npos) Invalid(text, "IPv6 addresses go in brackets");
  }
  if (host.empty()) Invalid(text, "empty host");
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (port.empty() || ec != std::errc() || end != port.data() + port.size() || value > 65535)
    Invalid(text, "port must be a number 0..65535");
  ep.kind = Kind::kTcp;
  ep.host = std::string(host);
  ep.port = static_cast<std::uint16_t>(value);
  return ep;
}

std::string Endpoint::ToString() const {
  if (kind == Kind::kUnix) return "unix://" + path;
  const bool v6 = host.find(':') != std::string::npos;
  return "tcp://" + (v6 ? "[" + host + "]" : host) + ":" + std::to_string(port);
}

bool Endpoint::IsLoopback() const {
  if (kind != Kind::kTcp) return false;
  return host == "localhost" || host == "::1" || host.starts_with("127.");
}

}  // namespace canfleet::wire
