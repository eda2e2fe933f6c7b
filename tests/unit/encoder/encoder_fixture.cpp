#include "tests/unit/encoder/encoder_fixture.hpp"

#include <cstdio>
#include <cstring>
#include <memory>

namespace canfleet::devices::encoder::test {

std::string LeHex(std::uint64_t value, int size) {
  std::string out;
  char buf[4];
  for (int i = 0; i < size; ++i) {
    std::snprintf(buf, sizeof buf, "%02X", static_cast<unsigned>((value >> (8 * i)) & 0xFF));
    out += buf;
  }
  return out;
}

namespace {

std::string Multiplexer(std::uint16_t index, std::uint8_t sub) {
  return LeHex(index, 2) + LeHex(sub, 1);
}

}  // namespace

std::string SdoWrite(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size) {
  static const char* kCommand[] = {"", "2F", "2B", "27", "23"};
  return std::string("605#") + kCommand[size] + Multiplexer(index, sub) + LeHex(value, size) +
         std::string(static_cast<std::size_t>(2 * (4 - size)), '0');
}

std::string SdoWritten(std::uint16_t index, std::uint8_t sub) {
  return "585#60" + Multiplexer(index, sub) + "00000000";
}

std::string SdoAborted(std::uint16_t index, std::uint8_t sub, std::uint32_t code) {
  return "585#80" + Multiplexer(index, sub) + LeHex(code, 4);
}

std::string SdoRead(std::uint16_t index, std::uint8_t sub) {
  return "605#40" + Multiplexer(index, sub) + "00000000";
}

std::string Emcy(std::uint16_t code, std::uint8_t channel, std::uint8_t description) {
  return "085#" + LeHex(code, 2) + "01" + LeHex(channel, 1) + LeHex(description, 1) + "000000";
}

std::uint32_t Real32Bits(float value) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

EncoderTest::EncoderTest()
    : node_port_(bus_.Attach("encoder")),
      master_(bus_, "master"),
      node_(std::make_unique<EncoderValveController>(), scheduler_, {&node_port_},
            NodeSettings{{PortSettings{kNodeId, 4}}, {}, std::nullopt, {}}) {
  node_.Start();
  EXPECT_EQ(master_.Take(), std::vector<std::string>{"705#00"});
  Advance(1ms);  // the first evaluation after power-on
}

std::vector<std::string> EncoderTest::Frames() {
  std::vector<std::string> out(backlog_.begin(), backlog_.end());
  backlog_.clear();
  for (auto& f : master_.Take())
    out.push_back(std::move(f));
  return out;
}

std::vector<std::string> EncoderTest::Frames(std::string_view prefix) {
  std::vector<std::string> out;
  for (auto& f : Frames()) {
    if (f.starts_with(prefix)) out.push_back(std::move(f));
  }
  return out;
}

std::string EncoderTest::Sdo(std::string_view request) {
  for (auto& f : master_.Take())
    backlog_.push_back(std::move(f));
  master_.Send(request);
  std::string answer;
  for (auto& f : master_.Take()) {
    if (answer.empty() && f.starts_with("585#"))
      answer = std::move(f);
    else
      backlog_.push_back(std::move(f));
  }
  return answer;
}

std::string EncoderTest::TryWrite(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size) {
  return Sdo(SdoWrite(index, sub, value, size));
}

void EncoderTest::Write(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size) {
  EXPECT_EQ(TryWrite(index, sub, value, size), SdoWritten(index, sub));
}

std::int64_t EncoderTest::Read(std::uint16_t index, std::uint8_t sub, bool is_signed) {
  std::string answer = Sdo(SdoRead(index, sub));
  EXPECT_EQ(answer.size(), 4u + 16u) << answer;
  if (answer.size() != 20) return 0;
  const std::string cmd = answer.substr(4, 2);
  const int size = cmd == "4F" ? 1 : cmd == "4B" ? 2 : cmd == "47" ? 3 : cmd == "43" ? 4 : 0;
  EXPECT_NE(size, 0) << answer;
  std::uint64_t value = 0;
  for (int i = 0; i < size; ++i)
    value |= std::stoull(answer.substr(static_cast<std::size_t>(12 + 2 * i), 2), nullptr, 16) << (8 * i);
  if (is_signed && size > 0 && size < 8 && ((value >> (8 * size - 1)) & 1))
    value |= ~std::uint64_t{0} << (8 * size);
  return static_cast<std::int64_t>(value);
}

}  // namespace canfleet::devices::encoder::test
