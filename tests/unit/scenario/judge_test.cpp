// Expectations judged by hand (issue 21): each kind passes, fails with what it saw instead, times
// out, and counts observations at both ends of its window but not outside it. Time is given by
// the test (scenario/judge.hpp has no clock).
#include "orchestrator/scenario/judge.hpp"

#include <gmock/gmock.h>
#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

namespace canfleet::scenario {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

const TimePoint kStart{std::chrono::seconds(100)};  // the scenario's start
const TimePoint kOpen = kStart + 5s;
const TimePoint kClose = kOpen + 1500ms;
const PortAddress kQuad6{"quad-6", "can0", 6};

topology::Expect Parse(const std::string& text) {
  topology::Expect e;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &e)) << text;
  return e;
}

std::unique_ptr<Judge> Make(const std::string& text, std::optional<PortAddress> port = kQuad6,
                            TimePoint open = kOpen, TimePoint close = kClose) {
  auto judge = MakeJudge(Parse(text), port, "can0", [](const std::string&, std::uint8_t id) {
    return id == 6 ? std::string("quad-6") : std::string();
  });
  judge->Open(kStart, open, close);
  return judge;
}

CanFrame Emcy(std::uint8_t node, std::uint16_t code, std::uint8_t reg = 0x11,
              std::array<std::uint8_t, 5> data = {0x05, 0x08, 0, 0, 0}) {
  return CanFrame::Data(0x080u + node, {static_cast<std::uint8_t>(code), static_cast<std::uint8_t>(code >> 8),
                                        reg, data[0], data[1], data[2], data[3], data[4]});
}

CanFrame Heartbeat(std::uint8_t node, std::uint8_t state) {
  return CanFrame::Data(0x700u + node, {state});
}

Sample Text(TimePoint t, std::string text, std::string unit = "") {
  Sample s;
  s.time = t;
  s.text = std::move(text);
  s.unit = std::move(unit);
  return s;
}

// ---- EMCY (CiA 301 §7.2.7.3.1) ----

TEST(EmcyJudgeTest, PassesAtTheFirstMatchingEmcyWithItsTime) {
  auto j = Make("emcy { node: 'quad-6' code: 0x8130 }");
  j->Frame("can0", Emcy(6, 0x8130), kOpen + 412ms);
  ASSERT_EQ(j->verdict().outcome, Outcome::kPassed);
  EXPECT_EQ(j->verdict().time, kOpen + 412ms);
  EXPECT_THAT(j->verdict().detail, HasSubstr("EMCY 8130h (register 11h, data 05 08 00 00 00) at t=5.412 s"));
}

TEST(EmcyJudgeTest, FailsAtCloseNamingTheEmcysSeenInstead) {
  auto j = Make("emcy { node: 'quad-6' code: 0x8131 }");
  j->Frame("can0", Emcy(6, 0x8130), kOpen + 100ms);
  j->Frame("can0", Emcy(5, 0x8131), kOpen + 200ms);  // another node's
  j->Frame("can1", Emcy(6, 0x8131), kOpen + 300ms);  // another bus
  EXPECT_FALSE(j->decided());
  j->Close();
  ASSERT_EQ(j->verdict().outcome, Outcome::kFailed);
  EXPECT_EQ(j->verdict().time, kClose);
  EXPECT_EQ(j->verdict().detail, "saw EMCY 8130h (register 11h, data 05 08 00 00 00) at t=5.100 s");
}

TEST(EmcyJudgeTest, TimesOutWhenNothingCame) {
  auto j = Make("emcy { node: 'quad-6' code: 0x8130 }");
  j->Close();
  EXPECT_EQ(j->verdict().outcome, Outcome::kFailed);
  EXPECT_EQ(j->verdict().detail, "no EMCY from quad-6 in the window");
}

TEST(EmcyJudgeTest, BothEndsOfTheWindowCountNothingOutsideDoes) {
  for (const TimePoint t : {kOpen, kClose}) {
    auto j = Make("emcy { node: 'quad-6' code: 0x8130 }");
    j->Frame("can0", Emcy(6, 0x8130), t);
    EXPECT_EQ(j->verdict().outcome, Outcome::kPassed);
  }
  for (const TimePoint t : {kOpen - 1ns, kClose + 1ns}) {
    auto j = Make("emcy { node: 'quad-6' code: 0x8130 }");
    j->Frame("can0", Emcy(6, 0x8130), t);
    EXPECT_FALSE(j->decided());
    j->Close();
    EXPECT_EQ(j->verdict().outcome, Outcome::kFailed);
  }
}

TEST(EmcyJudgeTest, ErrorRegisterAndMaskedManufacturerBytesMustMatch) {
  auto j = Make(
      "emcy { node: 'quad-6' code: 0x8130 error_register: 0x11 manufacturer: '05 08 00 00 00' "
      "manufacturer_mask: 'FF FF 00 00 00' }");
  j->Frame("can0", Emcy(6, 0x8130, 0x01), kOpen);                         // register differs
  j->Frame("can0", Emcy(6, 0x8130, 0x11, {0x06, 0x08, 0, 0, 0}), kOpen);  // channel differs
  EXPECT_FALSE(j->decided());
  j->Frame("can0", Emcy(6, 0x8130, 0x11, {0x05, 0x08, 0x7, 0, 0}), kOpen + 1ms);  // masked byte differs
  EXPECT_EQ(j->verdict().outcome, Outcome::kPassed);
}

TEST(NoEmcyJudgeTest, FailsAtTheFirstEmcyAndPassesAtClose) {
  auto quiet = Make("no_emcy { node: 'quad-6' }");
  quiet->Frame("can0", Emcy(5, 0x8130), kOpen);         // another node
  quiet->Frame("can0", Emcy(6, 0x8130), kClose + 1ns);  // after the window
  quiet->Close();
  EXPECT_EQ(quiet->verdict().outcome, Outcome::kPassed);

  auto any = Make("no_emcy {}", std::nullopt);
  any->Frame("can0", Emcy(6, 0x0000), kClose);
  ASSERT_EQ(any->verdict().outcome, Outcome::kFailed);
  EXPECT_EQ(any->verdict().detail,
            "saw EMCY 0000h (register 11h, data 05 08 00 00 00) from quad-6 at t=6.500 s");

  auto code = Make("no_emcy { code: 0x8130 }", std::nullopt);
  code->Frame("can0", Emcy(9, 0x8250), kOpen);
  EXPECT_FALSE(code->decided());
  code->Frame("can0", Emcy(9, 0x8130), kOpen);
  EXPECT_THAT(code->verdict().detail, HasSubstr("from can0 node-ID 9"));
}

// ---- NMT state from heartbeats (CiA 301 §7.2.8.3.2) ----

TEST(NmtJudgeTest, EventuallyPassesOnAHeartbeatOfThatState) {
  auto j = Make("nmt { node: 'quad-6' state: 'pre-operational' }");
  j->Observe(Text(kOpen, "operational"));
  j->Frame("can0", Heartbeat(6, 0x05), kOpen + 200ms);
  EXPECT_FALSE(j->decided());
  j->Frame("can0", Heartbeat(6, 0x7F), kOpen + 400ms);
  EXPECT_EQ(j->verdict().outcome, Outcome::kPassed);
  EXPECT_EQ(j->verdict().time, kOpen + 400ms);
}

TEST(NmtJudgeTest, EventuallyFailsWithTheStatesSeen) {
  auto j = Make("nmt { node: 'quad-6' state: 'pre-operational' }");
  j->Observe(Text(kOpen, "operational"));
  j->Close();
  EXPECT_EQ(j->verdict().detail, "was operational at t=5.000 s");
}

TEST(NmtJudgeTest, ThroughoutFailsAtTheFirstOtherStateAndPassesAtClose) {
  auto j =
      MakeJudge(Parse("throughout: true nmt { node: 'quad-6' state: 'operational' }"), kQuad6, "can0", {});
  j->Open(kStart, kOpen, kClose);
  j->Observe(Text(kOpen, "operational"));
  j->Frame("can0", Heartbeat(6, 0x05), kOpen + 200ms);
  j->Frame("can0", Heartbeat(6, 0x7F), kClose + 1ms);  // after the window: not judged
  j->Close();
  EXPECT_EQ(j->verdict().outcome, Outcome::kPassed);
  EXPECT_EQ(j->verdict().detail, "from operational at t=5.000 s to operational (heartbeat) at t=5.200 s");

  auto k =
      MakeJudge(Parse("throughout: true nmt { node: 'quad-6' state: 'operational' }"), kQuad6, "can0", {});
  k->Open(kStart, kOpen, kClose);
  k->Observe(Text(kOpen, "operational"));
  k->Frame("can0", Heartbeat(6, 0x7F), kClose);
  EXPECT_EQ(k->verdict().outcome, Outcome::kFailed);
  EXPECT_EQ(k->verdict().detail, "was pre-operational (heartbeat) at t=6.500 s");
}

TEST(NmtJudgeTest, AnInstantIsJudgedOnItsFirstObservation) {
  auto j = Make("nmt { node: 'quad-6' state: 'stopped' }", kQuad6, kOpen, kOpen);
  j->Observe(Text(kOpen, "stopped"));
  EXPECT_EQ(j->verdict().outcome, Outcome::kPassed);
  auto k = Make("nmt { node: 'quad-6' state: 'stopped' }", kQuad6, kOpen, kOpen);
  k->Observe(Text(kOpen, "operational"));
  EXPECT_EQ(k->verdict().outcome, Outcome::kFailed);
}

// ---- SDO ----

Sample Upload(TimePoint t, std::vector<std::uint8_t> data) {
  Sample s;
  s.time = t;
  s.data = std::move(data);
  return s;
}

TEST(SdoJudgeTest, ValueAsItsTypeAndWhatWasReadInstead) {
  auto j = Make("sdo { node: 'quad-6' index: 0x1003 subindex: 1 type: 'u32' value: '0x08058130' }");
  j->Observe(Upload(kOpen, {0x30, 0x81, 0x05, 0x08}));
  EXPECT_EQ(j->verdict().outcome, Outcome::kPassed);

  auto k = Make("sdo { node: 'quad-6' index: 0x1003 subindex: 1 type: 'u32' value: '0x08068130' }");
  k->Observe(Upload(kOpen, {0x30, 0x81, 0x05, 0x08}));
  k->Close();
  EXPECT_EQ(k->verdict().detail, "was 134578480 (08058130h) at t=5.000 s");
}

TEST(SdoJudgeTest, MaskComparesOnlyItsBits) {
  auto j = Make("sdo { node: 'quad-6' index: 0x1001 type: 'u8' value: '1' mask: 0x01 }");
  j->Observe(Upload(kOpen, {0x11}));
  EXPECT_EQ(j->verdict().outcome, Outcome::kPassed);
}

TEST(SdoJudgeTest, AnAbortIsAnObservation) {
  Sample aborted;
  aborted.time = kOpen;
  aborted.abort = 0x06020000;
  auto expected = Make("sdo { node: 'quad-6' index: 0x2FFF type: 'u8' abort: 0x06020000 }");
  expected->Observe(aborted);
  EXPECT_EQ(expected->verdict().outcome, Outcome::kPassed);

  auto value = Make("sdo { node: 'quad-6' index: 0x1001 type: 'u8' value: '0' }", kQuad6, kOpen, kOpen);
  value->Observe(aborted);
  EXPECT_EQ(value->verdict().outcome, Outcome::kFailed);
  EXPECT_EQ(value->verdict().detail, "was SDO abort 06020000h at t=5.000 s");
}

TEST(SdoJudgeTest, AReadThatNeverCompletedSaysSo) {
  auto j = Make("sdo { node: 'quad-6' index: 0x1001 type: 'u8' value: '0' }");
  Sample lost;
  lost.time = kOpen;
  lost.error = "SDO timeout";
  j->Observe(lost);
  j->Close();
  EXPECT_EQ(j->verdict().detail, "was SDO timeout at t=5.000 s");
}

// ---- simulated I/O ----

TEST(IoJudgeTest, NumbersWithinToleranceTextsExactlyRangesInclusive) {
  auto number = Make("io { node: 'quad-6' name: 'OUT1.current_mA' value: '1000' }");
  number->Observe(Text(kOpen, "999.6", "mA"));
  EXPECT_EQ(number->verdict().outcome, Outcome::kPassed);
  EXPECT_EQ(number->verdict().detail, "999.6 mA at t=5.000 s");

  auto text = Make("io { node: 'psu' name: 'PS.state' value: 'on' }");
  text->Observe(Text(kOpen, "fault_latched"));
  text->Close();
  EXPECT_EQ(text->verdict().detail, "was fault_latched at t=5.000 s");

  auto range = Make("io { node: 'quad-6' name: 'OUT1.current_mA' min: 0 max: 10 }");
  range->Observe(Text(kOpen, "10.5", "mA"));
  EXPECT_FALSE(range->decided());
  range->Observe(Text(kOpen + 100ms, "10", "mA"));
  EXPECT_EQ(range->verdict().outcome, Outcome::kPassed);
}

// ---- frames ----

TEST(FramesJudgeTest, AtLeastPassesWhenReached) {
  auto j = Make("frames { cob_id: 0x185 at_least: 2 }");
  const CanFrame pdo = CanFrame::Data(0x185, {1, 2});
  j->Frame("can0", pdo, kOpen + 10ms);
  EXPECT_FALSE(j->decided());
  j->Frame("can0", pdo, kOpen + 20ms);
  EXPECT_EQ(j->verdict().outcome, Outcome::kPassed);
  EXPECT_EQ(j->verdict().detail, "seen 2x by t=5.020 s");
}

TEST(FramesJudgeTest, NotSeenFailsAtTheFirstAndPassesAtClose) {
  auto j = Make("frames { cob_id: 0x705 at_most: 0 }");
  j->Frame("can0", CanFrame::Data(0x706, {5}), kOpen);
  j->Close();
  EXPECT_EQ(j->verdict().outcome, Outcome::kPassed);
  auto k = Make("frames { cob_id: 0x705 at_most: 0 }");
  k->Frame("can0", CanFrame::Data(0x705, {5}), kClose);
  EXPECT_EQ(k->verdict().outcome, Outcome::kFailed);
  EXPECT_EQ(k->verdict().detail, "seen 1x, the last 705h#05 at t=6.500 s");
}

TEST(FramesJudgeTest, PeriodWithinToleranceIncludingTheWindowsEnds) {
  const CanFrame hb = Heartbeat(5, 0x05);
  auto j = Make("frames { cob_id: 0x705 period_ms: 500 tolerance_ms: 50 }");
  for (const auto t : {400ms, 900ms, 1420ms})
    j->Frame("can0", hb, kOpen + t);
  j->Close();  // the last gap, 1420 -> 1500 ms, is within 550 ms
  ASSERT_EQ(j->verdict().outcome, Outcome::kPassed) << j->verdict().detail;
  EXPECT_EQ(j->verdict().detail, "seen 3x, gaps 500.0..520.0 ms, the last 705h#05");

  auto early = Make("frames { cob_id: 0x705 period_ms: 500 tolerance_ms: 50 }");
  early->Frame("can0", hb, kOpen + 100ms);
  early->Frame("can0", hb, kOpen + 400ms);
  EXPECT_EQ(early->verdict().detail, "a gap of 300.0 ms between two frames, up to t=5.400 s");

  auto stopped = Make("frames { cob_id: 0x705 period_ms: 500 tolerance_ms: 50 }");
  stopped->Frame("can0", hb, kOpen + 100ms);
  stopped->Close();
  EXPECT_EQ(stopped->verdict().detail, "a gap of 1400.0 ms since the last one at t=5.100 s");
}

TEST(FramesJudgeTest, PayloadComparedUnderItsMask) {
  auto j = Make("frames { cob_id: 0x185 data: 'E8 03' data_mask: 'FF 0F' }");
  j->Frame("can0", CanFrame::Data(0x185, {0xE8, 0xF3, 0x00}), kOpen);
  j->Close();
  EXPECT_EQ(j->verdict().outcome, Outcome::kPassed);
  auto k = Make("frames { cob_id: 0x185 data: 'E8 03' }");
  k->Frame("can0", CanFrame::Data(0x185, {0xE9, 0x03}), kOpen);
  EXPECT_EQ(k->verdict().detail, "saw 185h#E9 03 at t=5.000 s");
}

// ---- bus and controller ----

Sample Load(TimePoint t, double percent) {
  Sample s;
  s.time = t;
  s.load_percent = percent;
  return s;
}

TEST(BusJudgeTest, LoadBelowEverySampleAboveSomeSample) {
  auto below = Make("bus { load_below: 50 }", std::nullopt);
  below->Observe(Load(kOpen, 12.5));
  below->Observe(Load(kOpen + 100ms, 30));
  below->Close();
  EXPECT_EQ(below->verdict().detail, "highest load 30.0% at t=5.100 s");
  auto over = Make("bus { load_below: 50 }", std::nullopt);
  over->Observe(Load(kOpen + 100ms, 97.3));
  EXPECT_EQ(over->verdict().detail, "load 97.3% at t=5.100 s");
  auto above = Make("bus { load_above: 90 }", std::nullopt);
  above->Observe(Load(kOpen, 50));
  above->Close();
  EXPECT_EQ(above->verdict().detail, "highest load 50.0% at t=5.000 s");
}

TEST(BusJudgeTest, NoErrorFrames) {
  auto j = Make("bus { no_error_frames: true }", std::nullopt);
  j->Frame("can0", CanFrame::Data(0x185, {1}), kOpen);
  j->Close();
  EXPECT_EQ(j->verdict().outcome, Outcome::kPassed);
  auto k = Make("bus { no_error_frames: true }", std::nullopt);
  CanFrame error = CanFrame::Data(0x185, {});
  error.flags = CanFrame::kError;
  k->Frame("can0", error, kOpen + 1ms);
  EXPECT_EQ(k->verdict().outcome, Outcome::kFailed);
}

TEST(ControllerJudgeTest, SeesBusOff) {
  auto j = Make("controller { node: 'quad-6' state: 'bus-off' }");
  j->Observe(Text(kOpen, "error-active"));
  j->Observe(Text(kOpen + 10ms, "bus-off"));
  EXPECT_EQ(j->verdict().outcome, Outcome::kPassed);
}

}  // namespace
}  // namespace canfleet::scenario
