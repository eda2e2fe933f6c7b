#include "tests/unit/devices/quad_fixture.hpp"

#include "tests/support/sdo_script.hpp"

namespace canfleet::devices::test {

namespace {
/// QuadTest::kNodeId, for the free functions below (the constant is the fixture's, protected).
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

std::string Emcy(std::uint16_t code, std::uint8_t reg, std::uint8_t channel, std::uint8_t description) {
  return "085#" + LeHex(code, 2) + LeHex(reg, 1) + LeHex(channel, 1) + LeHex(description, 1) + "000000";
}

QuadTest::QuadTest(std::filesystem::path state_dir)
    : node_port_(bus_.Attach("quad")),
      master_(bus_, "master"),
      node_(std::make_unique<QuadController>(), scheduler_, {&node_port_},
            NodeSettings{{PortSettings{kNodeId, 4}}, std::move(state_dir), std::nullopt, {}}) {
  node_.Start();
  EXPECT_EQ(master_.Take(), std::vector<std::string>{"705#00"});
}

void QuadTest::Start() {
  Send("000#0105");
  Advance(1ms);
}

std::vector<std::string> QuadTest::Frames() {
  return canfleet::test::TakeFrames(master_, backlog_);
}

std::vector<std::string> QuadTest::Frames(std::string_view prefix) {
  return canfleet::test::TakeFrames(master_, backlog_, prefix);
}

std::string QuadTest::Sdo(std::string_view request) {
  return canfleet::test::ExchangeSdo(master_, backlog_, kNodeId, request);
}

std::string QuadTest::TryWrite(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size) {
  return Sdo(SdoWrite(index, sub, value, size));
}

void QuadTest::Write(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size) {
  EXPECT_EQ(TryWrite(index, sub, value, size), SdoWritten(index, sub));
}

std::int64_t QuadTest::Read(std::uint16_t index, std::uint8_t sub, bool is_signed) {
  return canfleet::test::ExpeditedValue(Sdo(SdoRead(index, sub)), is_signed);
}

void QuadTest::SilenceTpdoTimers() {
  for (std::uint16_t index = 0x1800; index <= 0x1803; ++index)
    Write(index, 5, 0, 2);
}

}  // namespace canfleet::devices::test
