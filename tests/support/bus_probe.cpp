#include "tests/support/bus_probe.hpp"

#include <stdexcept>

namespace canfleet::test {

namespace {
int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}
}  // namespace

CanFrame Frame(std::string_view text) {
  auto hash = text.find('#');
  if (hash == std::string_view::npos || hash == 0)
    throw std::invalid_argument("no '#' in frame: " + std::string(text));
  CanFrame f;
  auto id_text = text.substr(0, hash);
  for (char c : id_text) {
    int d = HexDigit(c);
    if (d < 0) throw std::invalid_argument("bad id in frame: " + std::string(text));
    f.id = (f.id << 4) | static_cast<std::uint32_t>(d);
  }
  if (id_text.size() > 3) f.flags |= CanFrame::kExtended;
  auto data = text.substr(hash + 1);
  if (!data.empty() && (data[0] == 'R' || data[0] == 'r')) {
    f.flags |= CanFrame::kRemote;
    f.dlc = data.size() > 1 ? static_cast<std::uint8_t>(data[1] - '0') : 0;
    return f;
  }
  std::string hex;
  for (char c : data) {
    if (c == ' ' || c == '.') continue;
    if (HexDigit(c) < 0) throw std::invalid_argument("bad data in frame: " + std::string(text));
    hex += c;
  }
  if (hex.size() % 2 != 0 || hex.size() > 16)
    throw std::invalid_argument("bad data length: " + std::string(text));
  f.dlc = static_cast<std::uint8_t>(hex.size() / 2);
  for (std::size_t i = 0; i < f.dlc; ++i) {
    f.data[i] = static_cast<std::uint8_t>(HexDigit(hex[2 * i]) << 4 | HexDigit(hex[2 * i + 1]));
  }
  return f;
}

BusProbe::BusProbe(LoopbackBus& bus, std::string name) : port_(bus.Attach(std::move(name))) {
  port_.OnReceive([this](const CanFrame& f, BusTime) { frames_.push_back(f); });
}

std::vector<std::string> BusProbe::Received() const {
  std::vector<std::string> out;
  for (const auto& f : frames_)
    out.push_back(ToCandump(f));
  return out;
}

std::vector<std::string> BusProbe::Take() {
  auto out = Received();
  frames_.clear();
  return out;
}

std::string BusProbe::Next() {
  if (frames_.empty()) return "";
  auto f = frames_.front();
  frames_.pop_front();
  return ToCandump(f);
}

}  // namespace canfleet::test
