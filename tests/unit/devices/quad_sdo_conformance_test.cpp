// SDO conformance of a running Quad against its EDS: a master (the project's SdoClient, over the
// loopback bus) reads every sub-object of quad-controller.eds and finds the EDS default (with the
// node-ID applied to $NODEID values), and writes every writable application parameter back with
// its default. The only answers that are not the default are the ones CiA 301 prescribes: 1003h
// entries beyond the number of errors (08000024h, CiA 301 §7.5.2.4) and write-only objects
// (06010001h).
#include <gtest/gtest.h>

#include <optional>

#include "node/canopen/eds/eds.hpp"
#include "node/canopen/sdo/sdo_client.hpp"
#include "tests/unit/devices/quad_fixture.hpp"

namespace canfleet::devices::test {
namespace {

using canopen::SdoAbort;

class QuadSdoConformanceTest : public QuadTest {
 protected:
  QuadSdoConformanceTest() : client_port_(bus_.Attach("sdo-client")), client_(client_port_, scheduler_) {
    client_port_.OnReceive([this](const CanFrame& frame, BusTime) { client_.OnFrame(frame); });
    // Inputs at 0 V / 0 % make the measured objects (7100h, 7130h) read their EDS default 0.
    for (int i = 1; i <= 4; ++i)
      SetNumber("IN" + std::to_string(i) + ".voltage_mV", 0);
    SetNumber("IN5.duty_pct", 0);
    SetNumber("IN6.duty_pct", 0);
    Advance(10ms);
  }

  struct Result {
    SdoAbort abort = SdoAbort::kGeneralError;
    canopen::Bytes data;
  };

  Result Upload(std::uint16_t index, std::uint8_t sub) {
    std::optional<Result> result;
    EXPECT_TRUE(client_.Upload(kNodeId, index, sub, canopen::SdoMode::kAuto,
                               [&](SdoAbort abort, canopen::Bytes data) {
                                 result = Result{abort, std::move(data)};
                               }));
    scheduler_.Advance(1ms);
    EXPECT_TRUE(result.has_value()) << std::hex << index << "." << int{sub};
    return result.value_or(Result{});
  }

  SdoAbort Download(std::uint16_t index, std::uint8_t sub, const canopen::Bytes& data) {
    std::optional<SdoAbort> result;
    EXPECT_TRUE(client_.Download(kNodeId, index, sub, data, canopen::SdoMode::kAuto,
                                 [&](SdoAbort abort) { result = abort; }));
    scheduler_.Advance(1ms);
    return result.value_or(SdoAbort::kTimeout);
  }

  static const canopen::EdsFile& Eds() {
    static const canopen::EdsFile eds = canopen::ReadEds(CANFLEET_QUAD_EDS);
    return eds;
  }

  LoopbackPort& client_port_;
  canopen::SdoClient client_;
};

TEST_F(QuadSdoConformanceTest, EveryObjectReadsItsEdsDefault) {
  std::size_t compared = 0;
  for (const auto& [index, object] : Eds().od.objects()) {
    for (const auto& [sub_index, sub] : object.subs) {
      Result r = Upload(index, sub_index);
      if (sub.access == canopen::Access::kWo) {
        EXPECT_EQ(r.abort, SdoAbort::kWriteOnly) << std::hex << index << "." << int{sub_index};
        continue;
      }
      if (index == 0x1003 && sub_index > 0) {
        EXPECT_EQ(r.abort, SdoAbort::kNoData) << "1003h." << int{sub_index} << " with no error recorded";
        continue;
      }
      ASSERT_EQ(r.abort, SdoAbort::kNone) << std::hex << index << "." << int{sub_index};
      EXPECT_EQ(r.data, sub.DefaultFor(kNodeId))
          << std::hex << index << "." << int{sub_index} << " " << sub.name;
      ++compared;
    }
  }
  // 464 sub-objects: all but the 6 write-only autozero entries and the 16 empty 1003h entries.
  EXPECT_EQ(compared, 442u);
}

// Writing a parameter's own default is always accepted (the value checks of quad_validators.hpp
// accept the factory configuration), in operational where output control may be written.
TEST_F(QuadSdoConformanceTest, EveryWritableApplicationParameterAcceptsItsDefault) {
  Start();
  std::size_t written = 0;
  for (const auto& [index, object] : Eds().od.objects()) {
    if (index < 0x2000 || index == 0x6125) continue;  // 6125h is a command ("zero")
    for (const auto& [sub_index, sub] : object.subs) {
      if (!canopen::IsWritable(sub.access)) continue;
      EXPECT_EQ(Download(index, sub_index, sub.DefaultFor(kNodeId)), SdoAbort::kNone)
          << std::hex << index << "." << int{sub_index} << " " << sub.name;
      ++written;
    }
  }
  EXPECT_EQ(written, 235u);  // not a vacuous pass: every writable entry of 2000h-9FFFh
}

}  // namespace
}  // namespace canfleet::devices::test
