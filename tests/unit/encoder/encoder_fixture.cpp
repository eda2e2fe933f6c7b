#include "tests/unit/encoder/encoder_fixture.hpp"

#include <cstring>
#include <memory>
#include "tests/support/sdo_script.hpp"

namespace canfleet::devices::encoder::test {

namespace {
/// EncoderTest::kNodeId, for the free functions below (the constant is the fixture's, protected).
constexpr std::uint8_t kNode = 5;
}  // namespace

std::string LeHex(std::uint64_t value, int size) {
  return canfleet::test::LeHex(value, size);
}

std::string SdoWrite(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size) {
  return canfleet::test::SdoDownload(kNode, index, sub, value, size);
}

std::string SdoWritten(std::uint16_t index, std::uint8_t sub) {
  return canfleet::test::SdoDownloaded(kNode, index, sub);
}

std::string SdoAborted(std::uint16_t index, std::uint8_t sub, std::uint32_t code) {
  return canfleet::test::SdoAbortFrom(kNode, index, sub, code);
}

std::string SdoRead(std::uint16_t index, std::uint8_t sub) {
  return canfleet::test::SdoUpload(kNode, index, sub);
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
  return canfleet::test::TakeFrames(master_, backlog_);
}

std::vector<std::string> EncoderTest::Frames(std::string_view prefix) {
  return canfleet::test::TakeFrames(master_, backlog_, prefix);
}

std::string EncoderTest::Sdo(std::string_view request) {
  return canfleet::test::ExchangeSdo(master_, backlog_, kNodeId, request);
}

std::string EncoderTest::TryWrite(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size) {
  return Sdo(SdoWrite(index, sub, value, size));
}

void EncoderTest::Write(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size) {
  EXPECT_EQ(TryWrite(index, sub, value, size), SdoWritten(index, sub));
}

std::int64_t EncoderTest::Read(std::uint16_t index, std::uint8_t sub, bool is_signed) {
  return canfleet::test::ExpeditedValue(Sdo(SdoRead(index, sub)), is_signed);
}

}  // namespace canfleet::devices::encoder::test
