#pragma once
/// @file "HOST:PORT" of a bound or connected TCP endpoint, IPv6 in brackets ("[::1]:29600"), as
/// logs and tcp:// endpoints (bus/wire/endpoint.hpp) write it. Shared by the broker's and the
/// control API's servers.

#include <asio/ip/tcp.hpp>
#include <string>

namespace canfleet::wire {

inline std::string TcpEndpointText(const asio::ip::tcp::endpoint& ep) {
  const std::string address = ep.address().to_string();
  return (ep.address().is_v6() ? "[" + address + "]" : address) + ":" + std::to_string(ep.port());
}

}  // namespace canfleet::wire
