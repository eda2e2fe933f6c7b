#include "node/process/node_options.hpp"

#include <stdexcept>

namespace canfleet::node {

BusSpec ParseBusSpec(const std::string& text) {
  BusSpec spec;
  if (text.rfind("socketcan:", 0) == 0) {
    spec.socketcan = true;
    spec.bus = text.substr(10);
    if (spec.bus.empty())
      throw std::invalid_argument("--bus " + text + ": no SocketCAN interface after 'socketcan:'");
    return spec;
  }
  auto at = text.find('@');
  if (at == std::string::npos || at == 0 || at + 1 == text.size()) {
    throw std::invalid_argument("--bus " + text +
                                ": expected BUS@tcp://HOST:PORT, BUS@unix:///PATH or socketcan:IFACE");
  }
  spec.bus = text.substr(0, at);
  spec.endpoint = text.substr(at + 1);
  if (spec.endpoint.rfind("tcp://", 0) != 0 && spec.endpoint.rfind("unix://", 0) != 0) {
    throw std::invalid_argument("--bus " + text + ": the broker endpoint must start with tcp:// or unix://");
  }
  return spec;
}

}  // namespace canfleet::node
