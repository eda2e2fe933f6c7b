#include "tests/unit/valve/valve_fixture.hpp"

#include "tests/support/sdo_script.hpp"

namespace canfleet::devices::valve::test {

namespace {
/// ValveTest::kNodeId, for the free functions below (the constant is the fixture's, protected).
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

std::string Emcy(std::uint16_t code, std::uint8_t reg, std::uint8_t channel, std::uint8_t description) {
  return "085#" + LeHex(code, 2) + LeHex(reg, 1) + LeHex(channel, 1) + LeHex(description, 1) + "000000";
}

std::string EmcyReset(std::uint8_t reg) {
  return "085#0000" + LeHex(reg, 1) + "0000000000";
}

ValveTest::ValveTest()
    : node_port_(bus_.Attach("valve")),
      master_(bus_, "master"),
      node_(std::make_unique<ValveController>(), scheduler_, {&node_port_},
            NodeSettings{{PortSettings{kNodeId, 4}}, {}, std::nullopt, {}}) {
  node_.Start();
  EXPECT_EQ(master_.Take(), std::vector<std::string>{"705#00"});
  Advance(10ms);  // the first runs after power-on
}

std::vector<std::string> ValveTest::Frames() {
  return canfleet::test::TakeFrames(master_, backlog_);
}

std::vector<std::string> ValveTest::Frames(std::string_view prefix) {
  return canfleet::test::TakeFrames(master_, backlog_, prefix);
}

std::string ValveTest::Sdo(std::string_view request) {
  return canfleet::test::ExchangeSdo(master_, backlog_, kNodeId, request);
}

std::string ValveTest::TryWrite(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size) {
  return Sdo(SdoWrite(index, sub, value, size));
}

void ValveTest::Write(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size) {
  EXPECT_EQ(TryWrite(index, sub, value, size), SdoWritten(index, sub));
}

void ValveTest::Refused(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size,
                        std::uint32_t code) {
  EXPECT_EQ(TryWrite(index, sub, value, size), SdoAborted(index, sub, code));
}

std::int64_t ValveTest::Read(std::uint16_t index, std::uint8_t sub, bool is_signed) {
  return canfleet::test::ExpeditedValue(Sdo(canfleet::test::SdoUpload(kNodeId, index, sub)), is_signed);
}

std::int64_t ValveTest::Value(std::uint16_t index, std::uint8_t sub) {
  const auto* s = od().Find(index, sub);
  if (!s) return 0;
  return canopen::IsSigned(s->type) ? canopen::DecodeSignedLe(s->value)
                                    : static_cast<std::int64_t>(canopen::DecodeUnsignedLe(s->value));
}

void ValveTest::SilenceTpdos() {
  Write(0x1800, 5, 0, 2);
  Write(0x1801, 5, 0, 2);
}

}  // namespace canfleet::devices::valve::test
