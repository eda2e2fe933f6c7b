// The scenario runner on simulated time (issue 21): action steps at their times, windows timed
// from the start, from a step, or from when an earlier expectation passed; a window whose anchor
// failed is skipped; polled reads while a window is open, a read answered after the close still
// counts, one never answered is given up; the done hook once everything is decided.
#include "orchestrator/scenario/scenario_runner.hpp"

#include <gmock/gmock.h>
#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <deque>

namespace canfleet::scenario {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

/// Answers reads from values the test sets; SDO answers wait until the test releases them.
class FakeProbe final : public FleetProbe {
 public:
  void ReadSdo(const PortAddress&, std::size_t, std::uint16_t, std::uint8_t, SdoDone done) override {
    ++sdo_reads;
    pending_sdo.push_back(std::move(done));
  }
  void ReadIo(const std::string&, const std::string&, IoDone done) override { done({}, io_value, "mA"); }
  std::string NmtState(const PortAddress&) const override { return nmt; }
  std::string ControllerState(const PortAddress&) const override { return controller; }
  double LoadPercent(const std::string&) const override { return load; }

  void AnswerSdo(std::vector<std::uint8_t> data) {
    auto done = std::move(pending_sdo.front());
    pending_sdo.pop_front();
    done(std::nullopt, std::move(data), {});
  }

  std::string nmt = "operational", controller = "error-active", io_value = "0";
  double load = 5;
  int sdo_reads = 0;
  std::deque<SdoDone> pending_sdo;
};

topology::Topology Parse(const std::string& scenario) {
  topology::Topology t;
  const std::string text = R"(name: "t" bus { name: "can0" }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0" }
node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0" }
)" + scenario;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &t)) << text;
  return t;
}

CanFrame Emcy(std::uint8_t node, std::uint16_t code) {
  return CanFrame::Data(0x080u + node, {static_cast<std::uint8_t>(code), static_cast<std::uint8_t>(code >> 8),
                                        0x11, 0, 0, 0, 0, 0});
}

class ScenarioRunnerTest : public ::testing::Test {
 protected:
  void Run(const std::string& scenario) {
    topology_ = Parse(scenario);
    runner_ =
        std::make_unique<ScenarioRunner>(scheduler_, topology_, probe_,
                                         ScenarioRunner::Hooks{
                                             .act =
                                                 [this](const topology::Step& s) {
                                                   acted_.push_back({s.name(), scheduler_.Now()});
                                                 },
                                             .decided = [this](const Result& r) { decided_.push_back(r); },
                                             .began = {},
                                             .done = [this] { ++done_; },
                                         });
    runner_->Start();
  }
  TimePoint T(Duration d) const { return TimePoint{} + d; }
  const Result* Decided(const std::string& name) const {
    for (const auto& r : decided_)
      if (r.name == name) return &r;
    return nullptr;
  }

  SimulatedScheduler scheduler_;
  FakeProbe probe_;
  topology::Topology topology_;
  std::unique_ptr<ScenarioRunner> runner_;
  std::vector<std::pair<std::string, TimePoint>> acted_;
  std::vector<Result> decided_;
  int done_ = 0;
};

// The issue's example: heartbeat loss at 5 s, EMCY 8130h from node 6 within 1.5 s after it.
TEST_F(ScenarioRunnerTest, AWindowAfterANamedStepOpensWhenTheStepRuns) {
  Run(R"(
scenario { at_ms: 5000 name: "cut-hb" inject { kind: HEARTBEAT_LOSS node: "quad-5" } }
scenario { name: "emcy" expect { after: "cut-hb" within_ms: 1500 emcy { node: "quad-6" code: 0x8130 } } }
)");
  scheduler_.Advance(5s);
  ASSERT_EQ(acted_.size(), 1u);
  EXPECT_EQ(acted_[0].second, T(5s));
  runner_->Frame("can0", Emcy(6, 0x8130), T(4900ms));  // before the window: not judged
  EXPECT_TRUE(decided_.empty());
  runner_->Frame("can0", Emcy(6, 0x8130), T(6200ms));
  ASSERT_EQ(decided_.size(), 1u);
  EXPECT_EQ(decided_[0].verdict.outcome, Outcome::kPassed);
  EXPECT_EQ(decided_[0].description, "EMCY 8130h from quad-6 within 1500 ms after cut-hb");
  EXPECT_EQ(*decided_[0].opened, T(5s));
  EXPECT_EQ(done_, 1);
}

TEST_F(ScenarioRunnerTest, AWindowTimesOutAtItsEnd) {
  Run(R"(scenario { at_ms: 1000 name: "e" expect { within_ms: 500 emcy { node: "quad-6" code: 0x8130 } } })");
  scheduler_.Advance(1499ms);
  EXPECT_TRUE(decided_.empty());
  scheduler_.Advance(1ms);
  ASSERT_EQ(decided_.size(), 1u);
  EXPECT_EQ(decided_[0].verdict.outcome, Outcome::kFailed);
  EXPECT_EQ(decided_[0].verdict.time, T(1500ms));
  EXPECT_EQ(done_, 1);
}

TEST_F(ScenarioRunnerTest, AfterAnExpectationCountsFromWhatItSawAndSkipsWhenItFailed) {
  Run(R"(
scenario { name: "emcy" expect { within_ms: 2000 emcy { node: "quad-6" code: 0x8130 } } }
scenario { at_ms: 100 name: "preop" expect { after: "emcy" within_ms: 300 nmt { node: "quad-6" state: "pre-operational" } } }
scenario { name: "never" expect { within_ms: 100 emcy { node: "quad-6" code: 0x1000 } } }
scenario { name: "then" expect { after: "never" within_ms: 100 no_emcy {} } }
)");
  scheduler_.Advance(100ms);
  ASSERT_EQ(decided_.size(), 2u);  // "never" failed, "then" skipped
  EXPECT_EQ(Decided("then")->verdict.outcome, Outcome::kSkipped);
  EXPECT_THAT(Decided("then")->verdict.detail, HasSubstr("timed after never, which failed"));

  runner_->Frame("can0", Emcy(6, 0x8130), T(700ms));  // seen at 700 ms, delivered now (100 ms)
  ASSERT_NE(Decided("emcy"), nullptr);
  probe_.nmt = "pre-operational";
  scheduler_.Advance(700ms);  // 800 ms: the window opened at 700 + 100 ms
  ASSERT_NE(Decided("preop"), nullptr);
  EXPECT_EQ(Decided("preop")->verdict.outcome, Outcome::kPassed);
  EXPECT_EQ(*Decided("preop")->opened, T(800ms));
  EXPECT_EQ(done_, 1);
}

// An error reset right behind the EMCY it resets, in the same delivery: the window timed after the
// EMCY is open for the reset, but not judged on the EMCY that opened it.
TEST_F(ScenarioRunnerTest, AWindowOpenedByAFrameJudgesTheFramesAfterItNotThatOne) {
  Run(R"(
scenario { name: "emcy" expect { within_ms: 2000 emcy { node: "quad-6" code: 0x8140 } } }
scenario { name: "quiet" expect { after: "emcy" within_ms: 100 no_emcy { code: 0x8140 } } }
scenario { name: "reset" expect { after: "emcy" within_ms: 100 emcy { node: "quad-6" code: 0x0000 } } }
)");
  scheduler_.Advance(300ms);
  runner_->Frame("can0", Emcy(6, 0x8140), T(300ms));
  runner_->Frame("can0", Emcy(6, 0x0000), T(300ms));
  ASSERT_NE(Decided("reset"), nullptr);
  EXPECT_EQ(Decided("reset")->verdict.outcome, Outcome::kPassed);
  EXPECT_EQ(Decided("quiet"), nullptr);
  scheduler_.Advance(100ms);
  EXPECT_EQ(Decided("quiet")->verdict.outcome, Outcome::kPassed);
}

// A paced bus delivers a round's frames with their end-of-frame times, which can lie ahead of the
// scheduler's now: a window timed from such a frame opens at once and judges the next frames.
TEST_F(ScenarioRunnerTest, AWindowAnchoredOnAFrameAheadOfNowOpensAtOnce) {
  Run(R"(
scenario { name: "emcy" expect { within_ms: 2000 emcy { node: "quad-6" code: 0x8140 } } }
scenario { name: "reset" expect { after: "emcy" within_ms: 100 emcy { node: "quad-6" code: 0x0000 } } }
scenario { name: "state" expect { after: "emcy" nmt { node: "quad-6" state: "operational" } } }
)");
  scheduler_.Advance(300ms);
  runner_->Frame("can0", Emcy(6, 0x8140), T(300ms + 400us));
  runner_->Frame("can0", Emcy(6, 0x0000), T(300ms + 900us));
  ASSERT_NE(Decided("reset"), nullptr);
  EXPECT_EQ(Decided("reset")->verdict.outcome, Outcome::kPassed);
  ASSERT_NE(Decided("state"), nullptr);  // judged on a read taken as at its opening
  EXPECT_EQ(Decided("state")->verdict.outcome, Outcome::kPassed);
}

// The power supply's bus-off (topologies/scenarios/power-supply-24v-350w-bus-off.textproto) on a
// loaded machine: the broker's timer fires late, so the EMCY 8140h and the error reset 1 ms behind
// it reach the runner in one batch, both stamped before the scheduler's now. The window timed
// after the 8140h opens at the 8140h's time, not at the late now, and judges the reset.
TEST_F(ScenarioRunnerTest, AWindowAnchoredOnAFrameDeliveredLateJudgesTheFramesBehindIt) {
  Run(R"(
scenario { at_ms: 3000 name: "bus-off" inject { kind: BUS_OFF node: "quad-6" } }
scenario { name: "emcy" expect { after: "bus-off" within_ms: 3000 emcy { node: "quad-6" code: 0x8140 } } }
scenario { name: "reset" expect { after: "emcy" within_ms: 3000 emcy { node: "quad-6" code: 0x0000 } } }
scenario { name: "quiet" expect { after: "emcy" within_ms: 100 no_emcy { code: 0x8140 } } }
)");
  scheduler_.Advance(3500ms + 7ms);  // the round of 3.500 s runs 7 ms late
  runner_->Frame("can0", Emcy(6, 0x8140), T(3500ms));
  runner_->Frame("can0", Emcy(6, 0x0000), T(3501ms));
  ASSERT_NE(Decided("emcy"), nullptr);
  ASSERT_NE(Decided("reset"), nullptr);
  EXPECT_EQ(Decided("reset")->verdict.outcome, Outcome::kPassed) << Decided("reset")->verdict.detail;
  EXPECT_EQ(Decided("reset")->verdict.time, T(3501ms));
  EXPECT_EQ(*Decided("reset")->opened, T(3500ms));
  EXPECT_EQ(Decided("quiet"), nullptr);  // not judged on the 8140h that opened it
  scheduler_.Advance(100ms);
  ASSERT_NE(Decided("quiet"), nullptr);
  EXPECT_EQ(Decided("quiet")->verdict.outcome, Outcome::kPassed);
}

// A frame given before a window's timer fires (its end-of-frame time ahead of now, or a bus round
// that ran before the runner's timer on a loaded machine) is judged when the window opens.
TEST_F(ScenarioRunnerTest, AWindowOpenedByItsTimerJudgesTheFramesGivenBeforeIt) {
  Run(R"(
scenario { at_ms: 1000 name: "emcy" expect { within_ms: 500 emcy { node: "quad-6" code: 0x8140 } } }
scenario { at_ms: 1000 name: "early" expect { within_ms: 500 emcy { node: "quad-6" code: 0x1000 } } }
)");
  scheduler_.Advance(999ms);
  runner_->Frame("can0", Emcy(6, 0x1000), T(999ms));  // before its window
  runner_->Frame("can0", Emcy(6, 0x8140), T(1000ms + 300us));
  EXPECT_TRUE(decided_.empty());
  scheduler_.Advance(1ms);
  ASSERT_NE(Decided("emcy"), nullptr);
  EXPECT_EQ(Decided("emcy")->verdict.outcome, Outcome::kPassed);
  EXPECT_EQ(Decided("emcy")->verdict.time, T(1000ms + 300us));
  EXPECT_EQ(Decided("early"), nullptr);
  scheduler_.Advance(500ms);
  EXPECT_EQ(Decided("early")->verdict.outcome, Outcome::kFailed);
}

// A read passes at the time it was asked; its answer comes later. A window timed after it judges
// the frames seen between the question and the answer, which the runner was given before.
TEST_F(ScenarioRunnerTest, AWindowAfterAReadJudgesTheFramesSeenWhileItsAnswerWasOut) {
  Run(R"(
scenario { at_ms: 100 name: "entry" expect { within_ms: 1000 sdo { node: "quad-6" index: 0x1001 type: "u8" value: "1" } } }
scenario { name: "emcy" expect { after: "entry" within_ms: 500 emcy { node: "quad-6" code: 0x8140 } } }
)");
  scheduler_.Advance(100ms);
  ASSERT_EQ(probe_.sdo_reads, 1);
  runner_->Frame("can0", Emcy(6, 0x8140), T(99ms));  // before the question: not after the anchor
  scheduler_.Advance(30ms);
  runner_->Frame("can0", Emcy(6, 0x8140), T(120ms));
  scheduler_.Advance(30ms);
  probe_.AnswerSdo({0x01});
  ASSERT_NE(Decided("entry"), nullptr);
  EXPECT_EQ(Decided("entry")->verdict.time, T(100ms));
  ASSERT_NE(Decided("emcy"), nullptr);
  EXPECT_EQ(Decided("emcy")->verdict.outcome, Outcome::kPassed);
  EXPECT_EQ(Decided("emcy")->verdict.time, T(120ms));
}

// Each bus has its own rounds: another bus's frames behind the anchor's time may have been given
// before the anchor's own. They count; those before the anchor's time do not.
TEST_F(ScenarioRunnerTest, AWindowAnchoredOnAFrameJudgesAnotherBusFromTheAnchorsTime) {
  Run(R"(
bus { name: "can1" }
scenario { name: "emcy" expect { within_ms: 2000 emcy { node: "quad-6" code: 0x8140 } } }
scenario { name: "after" expect { after: "emcy" within_ms: 100 frames { bus: "can1" cob_id: 0x181 at_least: 1 } } }
scenario { name: "before" expect { after: "emcy" within_ms: 100 frames { bus: "can1" cob_id: 0x182 at_most: 0 } } }
)");
  scheduler_.Advance(305ms);
  runner_->Frame("can1", CanFrame::Data(0x182, {0x01}), T(299ms));
  runner_->Frame("can1", CanFrame::Data(0x181, {0x01}), T(301ms));
  runner_->Frame("can0", Emcy(6, 0x8140), T(300ms));
  ASSERT_NE(Decided("after"), nullptr);
  EXPECT_EQ(Decided("after")->verdict.outcome, Outcome::kPassed);
  EXPECT_EQ(Decided("after")->verdict.time, T(301ms));
  scheduler_.Advance(100ms);
  ASSERT_NE(Decided("before"), nullptr);
  EXPECT_EQ(Decided("before")->verdict.outcome, Outcome::kPassed) << Decided("before")->verdict.detail;
}

TEST_F(ScenarioRunnerTest, ThroughoutPollsTheWholeWindow) {
  Run(R"(scenario { name: "hold" expect { within_ms: 1000 throughout: true controller { node: "quad-6" state: "error-active" } } })");
  scheduler_.Advance(500ms);
  EXPECT_TRUE(decided_.empty());
  probe_.controller = "bus-off";
  scheduler_.Advance(10ms);
  ASSERT_EQ(decided_.size(), 1u);
  EXPECT_EQ(decided_[0].verdict.outcome, Outcome::kFailed);
  EXPECT_EQ(decided_[0].verdict.detail, "was bus-off at t=0.510 s");
}

TEST_F(ScenarioRunnerTest, AReadAskedInsideTheWindowCountsWhenItsAnswerComesAfterTheClose) {
  Run(R"(scenario { name: "entry" at_ms: 200 expect { sdo { node: "quad-6" index: 0x1001 type: "u8" value: "1" } } })");
  scheduler_.Advance(200ms);
  EXPECT_EQ(probe_.sdo_reads, 1);
  scheduler_.Advance(50ms);  // the instant's close has passed; the read is still out
  EXPECT_TRUE(decided_.empty());
  probe_.AnswerSdo({0x01});
  ASSERT_EQ(decided_.size(), 1u);
  EXPECT_EQ(decided_[0].verdict.outcome, Outcome::kPassed);
  EXPECT_EQ(decided_[0].verdict.time, T(200ms));
  EXPECT_EQ(decided_[0].description, "quad-6 1001h sub 0 = 1 at 200 ms after the start");
}

TEST_F(ScenarioRunnerTest, AReadNeverAnsweredIsGivenUpAfterTheGrace) {
  Run(R"(scenario { name: "entry" expect { within_ms: 150 sdo { node: "quad-6" index: 0x1001 type: "u8" value: "1" } } })");
  scheduler_.Advance(150ms);
  EXPECT_EQ(probe_.sdo_reads, 1);  // the next poll waits for the answer
  scheduler_.Advance(5s);
  ASSERT_EQ(decided_.size(), 1u);
  EXPECT_EQ(decided_[0].verdict.outcome, Outcome::kFailed);
  EXPECT_EQ(decided_[0].verdict.detail, "nothing observed in the window");
}

TEST_F(ScenarioRunnerTest, IoAndBusLoadArePolled) {
  probe_.io_value = "1000";
  probe_.load = 20;
  Run(R"(
scenario { name: "out" expect { within_ms: 500 io { node: "quad-6" name: "OUT1.current_mA" min: 0 max: 10 } } }
scenario { name: "load" expect { within_ms: 500 bus { load_below: 50 } } }
)");
  scheduler_.Advance(300ms);
  probe_.io_value = "0";
  scheduler_.Advance(100ms);
  ASSERT_NE(Decided("out"), nullptr);
  EXPECT_EQ(Decided("out")->verdict.outcome, Outcome::kPassed);
  EXPECT_EQ(Decided("out")->verdict.time, T(400ms));
  scheduler_.Advance(100ms);
  EXPECT_EQ(Decided("load")->verdict.outcome, Outcome::kPassed);
  EXPECT_EQ(done_, 1);
}

TEST_F(ScenarioRunnerTest, DoneWaitsForTheLastActionStep) {
  Run(R"(
scenario { name: "quick" expect { within_ms: 100 no_emcy {} } }
scenario { at_ms: 3000 clear {} }
)");
  scheduler_.Advance(1s);
  EXPECT_EQ(decided_.size(), 1u);
  EXPECT_EQ(done_, 0);
  scheduler_.Advance(2s);
  EXPECT_EQ(done_, 1);
  EXPECT_TRUE(runner_->Done());
}

// Issue 29: what monitors show of a run (telemetry's ScenarioStatus and Verdict): the counts of this
// run's verdicts, the step it is at (named, or what an action does), and each result's index
// among the expectations.
TEST_F(ScenarioRunnerTest, ProgressCountsVerdictsAndNamesTheLatestStep) {
  Run(R"(
scenario { at_ms: 1000 io { node: "quad-5" name: "IN1.voltage_mV" value: "1800" } }
scenario { at_ms: 2000 name: "cut-hb" inject { kind: HEARTBEAT_LOSS node: "quad-5" } }
scenario { name: "emcy" expect { after: "cut-hb" within_ms: 500 emcy { node: "quad-6" code: 0x8130 } } }
scenario { at_ms: 3000 expect { within_ms: 100 emcy { node: "quad-6" code: 0x1000 } } }
)");
  Progress p = runner_->GetProgress();
  EXPECT_TRUE(p.started);
  EXPECT_FALSE(p.done);
  EXPECT_EQ(p.expectations, 2u);
  EXPECT_EQ(p.pending, 2u);
  EXPECT_EQ(p.step, "");
  scheduler_.Advance(1s);
  p = runner_->GetProgress();
  EXPECT_EQ(p.step, "io quad-5 IN1.voltage_mV=1800");
  EXPECT_EQ(p.step_time, T(1s));
  scheduler_.Advance(1s);
  EXPECT_EQ(runner_->GetProgress().step, "emcy") << "the window opened by cut-hb is the latest to begin";
  runner_->Frame("can0", Emcy(6, 0x8130), T(2100ms));
  p = runner_->GetProgress();
  EXPECT_EQ(p.passed, 1u);
  EXPECT_EQ(p.pending, 1u);
  ASSERT_EQ(decided_.size(), 1u);
  EXPECT_EQ(decided_[0].index, 0);
  scheduler_.Advance(1100ms);  // 3.1 s: the unnamed expectation's window closed without its EMCY
  p = runner_->GetProgress();
  EXPECT_EQ(p.failed, 1u);
  EXPECT_EQ(p.pending, 0u);
  EXPECT_TRUE(p.done);
  EXPECT_EQ(p.step, "scenario[3]");
  ASSERT_EQ(decided_.size(), 2u);
  EXPECT_EQ(decided_[1].index, 1);
  EXPECT_EQ(runner_->Results()[1].index, 1);
}

TEST(ActionText, SaysWhatAnActionDoes) {
  const auto step = [](const std::string& text) {
    topology::Step s;
    EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &s)) << text;
    return ActionText(s);
  };
  EXPECT_EQ(step(R"(inject { kind: HEARTBEAT_LOSS node: "quad-5" })"), "inject heartbeat-loss quad-5");
  EXPECT_EQ(step(R"(inject { kind: PARTITION bus: "can0" })"), "inject partition can0");
  EXPECT_EQ(step(R"(clear { label: "hb-loss" })"), "clear hb-loss");
  EXPECT_EQ(step(R"(clear { fault_id: 3 })"), "clear 3");
  EXPECT_EQ(step(R"(clear {})"), "clear all");
  EXPECT_EQ(step(R"(nmt { action: NMT_START node: "quad-6" })"), "nmt start quad-6");
  EXPECT_EQ(step(R"(io { node: "psu-34" name: "ENABLE.level" value: "low" })"), "io psu-34 ENABLE.level=low");
  EXPECT_EQ(step(R"(sdo { node: "quad-5" index: 0x1017 subindex: 0 type: "u16" value: "1000" })"),
            "sdo write quad-5 1017h sub 0");
}

}  // namespace
}  // namespace canfleet::scenario
