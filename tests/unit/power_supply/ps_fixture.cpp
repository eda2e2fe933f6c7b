#include "tests/unit/power_supply/ps_fixture.hpp"

#include "tests/support/sdo_script.hpp"

namespace canfleet::devices::test {

namespace {
/// PsTest::kNodeId, for the free functions below (the constant is the fixture's, protected).
constexpr std::uint8_t kNode = 0x7F;
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
  return "0FF#" + LeHex(code, 2) + LeHex(reg, 1) + LeHex(channel, 1) + LeHex(description, 1) + "000000";
}

std::string EmcyReset(std::uint8_t reg) {
  return "0FF#0000" + LeHex(reg, 1) + "0000000000";
}

PsTest::PsTest(std::filesystem::path state_dir)
    : node_port_(bus_.Attach("ps")),
      master_(bus_, "master"),
      node_(std::make_unique<PowerSupply>(), scheduler_, {&node_port_},
            NodeSettings{{PortSettings{kNodeId, 4}}, std::move(state_dir), std::nullopt, {}}) {
  node_.Start();
  EXPECT_EQ(master_.Take(), std::vector<std::string>{"77F#00"});
  Advance(1ms);  // the first loop pass after power-on
}

void PsTest::Start() {
  Send("000#017F");
  Advance(1ms);
}

void PsTest::OnByCan() {
  Write(0x6200, 2, 0xFD, 1);
  Advance(1ms);
}

std::vector<std::string> PsTest::Frames() {
  return canfleet::test::TakeFrames(master_, backlog_);
}

std::vector<std::string> PsTest::Frames(std::string_view prefix) {
  return canfleet::test::TakeFrames(master_, backlog_, prefix);
}

std::string PsTest::Sdo(std::string_view request) {
  return canfleet::test::ExchangeSdo(master_, backlog_, kNodeId, request);
}

std::string PsTest::TryWrite(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size) {
  return Sdo(SdoWrite(index, sub, value, size));
}

void PsTest::Write(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size) {
  EXPECT_EQ(TryWrite(index, sub, value, size), SdoWritten(index, sub));
}

std::int64_t PsTest::Read(std::uint16_t index, std::uint8_t sub, bool is_signed) {
  return canfleet::test::ExpeditedValue(Sdo(SdoRead(index, sub)), is_signed);
}

}  // namespace canfleet::devices::test
