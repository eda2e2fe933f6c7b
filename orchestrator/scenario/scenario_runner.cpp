#include "orchestrator/scenario/scenario_runner.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <map>
#include <stdexcept>

namespace canfleet::scenario {

struct ScenarioRunner::Expectation {
  int step = 0;
  int index = 0;  ///< among the expectations
  const topology::Step* spec = nullptr;
  int anchor = -1;  ///< the step named by `after`, or -1 (the scenario's start)
  std::unique_ptr<Judge> judge;
  std::optional<PortAddress> port;
  std::size_t port_index = 0;
  std::string name, description;
  std::optional<TimePoint> opened;
  /// The frame its anchor saw: its window judges the frames of that bus behind it, not it.
  std::optional<FrameRef> after_frame;
  /// The frame that decided it (unset: a read, or its window's close).
  std::optional<FrameRef> decided_by;
  Verdict skipped;  ///< set when it cannot be judged (its anchor failed)
  bool scheduled = false, reading = false, closing = false, reported = false;
  std::unique_ptr<Timer> open_timer, poll_timer, close_timer, grace_timer;

  const Verdict& verdict() const { return skipped.outcome != Outcome::kPending ? skipped : judge->verdict(); }
  bool decided() const { return verdict().outcome != Outcome::kPending; }
};

bool ScenarioRunner::MayReadOnFrames() const {
  for (const auto& e : expects_) {
    if (e->decided()) continue;
    const auto kind = e->spec->expect().what_case();
    if (kind == topology::Expect::kSdo || kind == topology::Expect::kIo) return true;
  }
  return false;
}

struct ScenarioRunner::Action {
  int step = 0;
  std::unique_ptr<Timer> timer;
  bool ran = false;
};

namespace {

std::string StepName(const topology::Step& step, int index) {
  return step.name().empty() ? "scenario[" + std::to_string(index) + "]" : step.name();
}

/// The node and port an expectation is about ("" when none).
std::pair<std::string, std::uint32_t> NodeOf(const topology::Expect& e) {
  using E = topology::Expect;
  switch (e.what_case()) {
    case E::kEmcy:
      return {e.emcy().node(), e.emcy().port()};
    case E::kNoEmcy:
      return {e.no_emcy().node(), e.no_emcy().port()};
    case E::kNmt:
      return {e.nmt().node(), e.nmt().port()};
    case E::kSdo:
      return {e.sdo().node(), e.sdo().port()};
    case E::kIo:
      return {e.io().node(), 0};
    case E::kController:
      return {e.controller().node(), e.controller().port()};
    default:
      return {"", 0};
  }
}

std::string BusOf(const topology::Expect& e, const topology::Topology& topology) {
  std::string bus;
  if (e.has_frames()) bus = e.frames().bus();
  if (e.has_bus()) bus = e.bus().bus();
  if (bus.empty() && topology.bus_size() > 0) bus = topology.bus(0).name();
  return bus;
}

/// "... within 1500 ms after cut-hb", "... at 200 ms after the start".
std::string WindowText(const topology::Step& step, const std::string& what) {
  const topology::Expect& e = step.expect();
  const std::string anchor = e.after().empty() ? "the start" : e.after();
  if (e.within_ms() == 0) return what + " at " + std::to_string(step.at_ms()) + " ms after " + anchor;
  const bool whole = e.throughout() || e.has_no_emcy() || e.has_bus() ||
                     (e.has_frames() &&
                      (e.frames().has_at_most() || e.frames().period_ms() > 0 || !e.frames().data().empty()));
  std::string out = what + (whole ? " during " : " within ") + std::to_string(e.within_ms()) + " ms";
  if (step.at_ms() > 0) out += " from " + std::to_string(step.at_ms()) + " ms";
  return out + " after " + anchor;
}

}  // namespace

ScenarioRunner::ScenarioRunner(Scheduler& scheduler, const topology::Topology& topology, FleetProbe& probe,
                               Hooks hooks, RunnerOptions options)
    : scheduler_(scheduler), topology_(topology), probe_(probe), hooks_(std::move(hooks)), options_(options) {
  for (const auto& bus : topology_.bus())
    buses_.push_back(bus.name());
  std::map<std::string, int> named;
  auto namer = [this](const std::string& bus, std::uint8_t id) -> std::string {
    for (const auto& node : topology_.node())
      for (int p = 0; p < node.bus_size(); ++p) {
        const auto nid = node.node_id_size() == 1 ? node.node_id(0) : node.node_id(p);
        if (node.bus(p) == bus && nid == id) return node.name();
      }
    return "";
  };
  for (int i = 0; i < topology_.scenario_size(); ++i) {
    const topology::Step& step = topology_.scenario(i);
    if (!step.has_expect()) {
      auto action = std::make_unique<Action>();
      action->step = i;
      actions_.push_back(std::move(action));
    } else {
      auto e = std::make_unique<Expectation>();
      e->step = i;
      e->index = static_cast<int>(expects_.size());
      e->spec = &step;
      e->name = StepName(step, i);
      if (!step.expect().after().empty()) {
        const auto it = named.find(step.expect().after());
        if (it == named.end())
          throw std::invalid_argument(e->name + ": after: no earlier step is named " + step.expect().after());
        e->anchor = it->second;
      }
      const auto [node_name, port] = NodeOf(step.expect());
      if (!node_name.empty()) {
        const topology::Node* node = nullptr;
        for (const auto& n : topology_.node())
          if (n.name() == node_name) node = &n;
        if (node == nullptr || static_cast<int>(port) >= node->bus_size())
          throw std::invalid_argument(e->name + ": no node " + node_name + " with port " +
                                      std::to_string(port));
        const int p = static_cast<int>(port);
        e->port = PortAddress{
            node_name, node->bus(p),
            static_cast<std::uint8_t>(node->node_id_size() == 1 ? node->node_id(0) : node->node_id(p))};
        e->port_index = port;
      }
      e->judge = MakeJudge(step.expect(), e->port, BusOf(step.expect(), topology_), namer);
      e->description = WindowText(step, e->judge->Describe());
      expects_.push_back(std::move(e));
    }
    if (!step.name().empty()) named[step.name()] = i;
  }
}

ScenarioRunner::~ScenarioRunner() = default;

void ScenarioRunner::Start() {
  origin_ = scheduler_.Now();
  started_ = true;
  for (auto& action : actions_) {
    Action* a = action.get();
    a->timer = std::make_unique<Timer>(scheduler_, [this, a] {
      a->ran = true;
      Began(a->step);
      if (hooks_.act) hooks_.act(topology_.scenario(a->step));
      Anchored(a->step, scheduler_.Now());
      CheckDone();
    });
    a->timer->StartAt(origin_ + std::chrono::milliseconds(topology_.scenario(a->step).at_ms()));
  }
  Anchored(-1, origin_);
  CheckDone();
}

void ScenarioRunner::Anchored(int step, TimePoint anchor, std::optional<FrameRef> by) {
  for (auto& ptr : expects_) {
    Expectation& e = *ptr;
    if (e.anchor != step || e.scheduled || e.decided()) continue;
    e.scheduled = true;
    e.after_frame = by;
    const TimePoint open = anchor + std::chrono::milliseconds(e.spec->at_ms());
    e.open_timer = std::make_unique<Timer>(scheduler_, [this, &e, open] {
      e.opened = open;
      OpenWindow(e);
    });
    // A window already due, or one that opens at its anchor, opens now, not on a timer: the
    // frames that follow the anchor's in the same delivery (an error reset right after the EMCY it
    // resets) must find it open, and a paced bus delivers a round's frames with their end-of-frame
    // times, which may lie a little ahead of the scheduler's now (or, when its timer fired late,
    // behind it: OpenWindow).
    if (open <= scheduler_.Now() || e.spec->at_ms() == 0) {
      e.opened = open;
      OpenWindow(e);
    } else {
      e.open_timer->StartAt(open);
    }
  }
}

void ScenarioRunner::AnchorLost(int step, const std::string& why) {
  for (auto& ptr : expects_) {
    Expectation& e = *ptr;
    if (e.anchor != step || e.scheduled || e.decided()) continue;
    e.scheduled = true;
    e.skipped = {Outcome::kSkipped, scheduler_.Now(),
                 "not judged: it is timed after " + e.spec->expect().after() + ", which " + why};
    Finish(e);
  }
}

void ScenarioRunner::Began(int step) {
  last_step_ = step;
  last_step_time_ = scheduler_.Now();
  if (hooks_.began) hooks_.began(step);
}

void ScenarioRunner::OpenWindow(Expectation& e) {
  Began(e.step);
  const TimePoint now = scheduler_.Now();
  const auto within = std::chrono::milliseconds(e.spec->expect().within_ms());
  // A window opens at its time even when that has passed (a timer or a round of the bus that ran
  // late, an anchor decided by a read answered later): every frame the monitor saw from then on
  // counts, those already given (Replay) and those still to come, whenever they come. An instant
  // (within_ms 0) is judged on its first observation, which a read can make only now. A window
  // never closes before the runner opened it, so that a read can still look.
  const TimePoint open = within.count() == 0 ? std::max(*e.opened, now) : *e.opened;
  const TimePoint close = std::max({open, now, *e.opened + within});
  e.judge->Open(origin_, open, close);
  e.close_timer = std::make_unique<Timer>(scheduler_, [this, &e] { CloseWindow(e); });
  e.close_timer->StartAt(close);
  Replay(e);
  if (e.judge->decided()) return Finish(e);
  const Poll needs = e.judge->Needs();
  if (needs != Poll::kNone) {
    const Duration period =
        needs == Poll::kSdo || needs == Poll::kIo ? options_.remote_poll : options_.local_poll;
    if (close > open) {
      e.poll_timer = std::make_unique<Timer>(scheduler_, [this, &e, period] {
        e.poll_timer->StartAfter(period);
        PollOnce(e);
      });
      e.poll_timer->StartAfter(period);
    }
    PollOnce(e);
  }
  if (e.judge->decided()) Finish(e);
}

void ScenarioRunner::Replay(Expectation& e) {
  for (std::size_t i = 0; i < history_size_ && !e.judge->decided(); ++i) {
    const Heard& heard = HistoryAt(i);
    // The anchor's frame and those before it on its bus (same time on an unpaced bus) are not
    // behind it; frames of other buses count from the window's time (the judge's window).
    if (e.after_frame && heard.ref.bus == e.after_frame->bus && heard.ref.seq <= e.after_frame->seq) continue;
    e.judge->Frame(buses_[heard.ref.bus], heard.frame, heard.time);
    if (e.judge->decided()) e.decided_by = heard.ref;
  }
}

void ScenarioRunner::PollOnce(Expectation& e) {
  if (e.reading || e.decided() || e.closing) return;
  Sample sample;
  // A window opened at an anchor slightly ahead of now (a frame's bus time) reads from its opening.
  sample.time = std::max(scheduler_.Now(), e.judge->open_time());
  switch (e.judge->Needs()) {
    case Poll::kNmt:
      sample.text = probe_.NmtState(*e.port);
      break;
    case Poll::kController:
      sample.text = probe_.ControllerState(*e.port);
      if (sample.text.empty()) sample.error = e.port->node + " is not attached to " + e.port->bus;
      break;
    case Poll::kBusLoad:
      sample.load_percent = probe_.LoadPercent(BusOf(e.spec->expect(), topology_));
      break;
    case Poll::kSdo: {
      e.reading = true;
      const auto& sdo = e.spec->expect().sdo();
      probe_.ReadSdo(
          *e.port, e.port_index, static_cast<std::uint16_t>(sdo.index()),
          static_cast<std::uint8_t>(sdo.subindex()),
          [this, &e, sample, alive = std::weak_ptr<int>(alive_)](
              std::optional<std::uint32_t> abort, std::vector<std::uint8_t> data, std::string error) mutable {
            if (alive.expired()) return;
            sample.abort = abort;
            sample.data = std::move(data);
            sample.error = std::move(error);
            ReadDone(e, sample);
          });
      return;
    }
    case Poll::kIo: {
      e.reading = true;
      probe_.ReadIo(e.port->node, e.spec->expect().io().name(),
                    [this, &e, sample, alive = std::weak_ptr<int>(alive_)](
                        std::string error, std::string value, std::string unit) mutable {
                      if (alive.expired()) return;
                      sample.error = std::move(error);
                      sample.text = std::move(value);
                      sample.unit = std::move(unit);
                      ReadDone(e, sample);
                    });
      return;
    }
    case Poll::kNone:
      return;
  }
  e.judge->Observe(sample);
  if (e.judge->decided()) Finish(e);
}

void ScenarioRunner::ReadDone(Expectation& e, const Sample& sample) {
  e.reading = false;
  if (e.reported) return;
  e.judge->Observe(sample);
  if (e.closing && !e.judge->decided()) e.judge->Close();
  if (e.judge->decided()) Finish(e);
}

void ScenarioRunner::CloseWindow(Expectation& e) {
  if (e.decided()) return;
  if (e.poll_timer) e.poll_timer->Cancel();
  if (e.reading) {
    // The last read was asked inside the window: its answer still counts.
    e.closing = true;
    e.grace_timer = std::make_unique<Timer>(scheduler_, [this, &e] {
      e.reading = false;
      e.judge->Close();
      Finish(e);
    });
    e.grace_timer->StartAfter(options_.read_grace);
    return;
  }
  e.judge->Close();
  Finish(e);
}

void ScenarioRunner::Finish(Expectation& e) {
  if (e.reported || !e.decided()) return;
  e.reported = true;
  for (auto* timer : {e.open_timer.get(), e.poll_timer.get(), e.close_timer.get(), e.grace_timer.get()})
    if (timer) timer->Cancel();
  Result result;
  result.step = e.step;
  result.index = e.index;
  result.name = e.name;
  result.description = e.description;
  result.verdict = e.verdict();
  result.opened = e.opened;
  if (hooks_.decided) hooks_.decided(result);
  const Verdict& v = e.verdict();
  if (!e.spec->name().empty()) {
    if (v.outcome == Outcome::kPassed)
      Anchored(e.step, v.time, e.decided_by);
    else
      AnchorLost(e.step, v.outcome == Outcome::kFailed ? "failed" : "was not judged");
  }
  CheckDone();
}

void ScenarioRunner::Frame(const std::string& bus, const CanFrame& frame, TimePoint time) {
  const Heard heard{{BusIndex(bus), next_seq_++}, frame, time};
  // Only the windows open before this frame judge it here: a window that opens while it is judged
  // (timed after the expectation it decides) finds it in the history (Replay), and judges it only
  // if it is not the frame of its anchor (the window then starts with the next one).
  std::vector<Expectation*>& open = frame_targets_;
  open.clear();
  bool waiting = false;
  for (auto& ptr : expects_) {
    if (ptr->reported) continue;
    if (ptr->opened)
      open.push_back(ptr.get());
    else
      waiting = true;
  }
  if (waiting)
    Remember(heard);
  else
    history_size_ = 0;  // no window left to open
  for (Expectation* e : open) {
    if (e->reported) continue;
    e->judge->Frame(bus, frame, time);
    if (e->judge->decided()) {
      e->decided_by = heard.ref;
      Finish(*e);
    }
  }
}

std::size_t ScenarioRunner::BusIndex(const std::string& bus) {
  for (std::size_t i = 0; i < buses_.size(); ++i)
    if (buses_[i] == bus) return i;
  buses_.push_back(bus);
  return buses_.size() - 1;
}

void ScenarioRunner::Remember(const Heard& heard) {
  const TimePoint horizon = scheduler_.Now() - options_.frame_history;
  while (history_size_ > 0 && history_[history_head_].time < horizon) {
    history_head_ = (history_head_ + 1) % history_.size();
    --history_size_;
  }
  if (history_size_ == history_.size()) {
    std::vector<Heard> grown;
    grown.reserve(std::max<std::size_t>(64, 2 * history_.size()));
    for (std::size_t i = 0; i < history_size_; ++i)
      grown.push_back(HistoryAt(i));
    grown.resize(grown.capacity());
    history_ = std::move(grown);
    history_head_ = 0;
  }
  history_[(history_head_ + history_size_) % history_.size()] = heard;
  ++history_size_;
}

std::vector<Result> ScenarioRunner::Results() const {
  std::vector<Result> out;
  for (const auto& e : expects_)
    out.push_back({e->step, e->name, e->description, e->verdict(), e->opened, e->index});
  return out;
}

Progress ScenarioRunner::GetProgress() const {
  Progress p;
  p.expectations = expects_.size();
  for (const auto& e : expects_) {
    switch (e->reported ? e->verdict().outcome : Outcome::kPending) {
      case Outcome::kPassed:
        ++p.passed;
        break;
      case Outcome::kFailed:
        ++p.failed;
        break;
      case Outcome::kSkipped:
        ++p.skipped;
        break;
      case Outcome::kPending:
        ++p.pending;
        break;
    }
  }
  p.started = started_;
  p.done = Done();
  if (last_step_ >= 0 && last_step_ < topology_.scenario_size()) {
    const topology::Step& step = topology_.scenario(last_step_);
    p.step = !step.name().empty() ? step.name()
             : step.has_expect()  ? StepName(step, last_step_)
                                  : ActionText(step);
    p.step_time = last_step_time_;
  }
  return p;
}

std::string ActionText(const topology::Step& step) {
  const auto lower = [](std::string text) {
    for (char& c : text)
      c = c == '_' ? '-' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return text;
  };
  switch (step.action_case()) {
    case topology::Step::kInject: {
      const auto& f = step.inject();
      std::string text = "inject " + lower(control::FaultKind_Name(f.kind()));
      if (!f.node().empty()) text += " " + f.node();
      if (f.node().empty() && !f.bus().empty()) text += " " + f.bus();
      return text;
    }
    case topology::Step::kClear: {
      const auto& c = step.clear();
      if (c.fault_id() != 0) return "clear " + std::to_string(c.fault_id());
      if (!c.label().empty()) return "clear " + c.label();
      return "clear all";
    }
    case topology::Step::kIo:
      return "io " + step.io().node() + " " + step.io().name() + "=" + step.io().value();
    case topology::Step::kNmt: {
      std::string text = "nmt " + lower(control::NmtAction_Name(step.nmt().action()));
      if (text.rfind("nmt nmt-", 0) == 0) text = "nmt " + text.substr(8);
      if (!step.nmt().node().empty()) text += " " + step.nmt().node();
      return text;
    }
    case topology::Step::kSdo: {
      char index[16];
      std::snprintf(index, sizeof index, "%04Xh", step.sdo().index());
      return "sdo write " + step.sdo().node() + " " + index + " sub " + std::to_string(step.sdo().subindex());
    }
    default:
      return "step";
  }
}

bool ScenarioRunner::Done() const {
  if (!started_) return false;
  for (const auto& a : actions_)
    if (!a->ran) return false;
  for (const auto& e : expects_)
    if (!e->reported) return false;
  return true;
}

void ScenarioRunner::CheckDone() {
  if (done_reported_ || !Done()) return;
  done_reported_ = true;
  if (hooks_.done) hooks_.done();
}

}  // namespace canfleet::scenario
