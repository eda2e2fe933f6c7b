#include "orchestrator/transport/time_conductor.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <asio/post.hpp>
#include <stdexcept>

namespace canfleet::transport {

namespace {

std::string TimeText(TimePoint t) {
  return std::to_string(std::chrono::duration<double>(t.time_since_epoch()).count()) + " s";
}

/// Sets a flag for as long as it lives.
class FlagScope {
 public:
  explicit FlagScope(bool& flag) : flag_(flag) { flag_ = true; }
  ~FlagScope() { flag_ = false; }
  FlagScope(const FlagScope&) = delete;
  FlagScope& operator=(const FlagScope&) = delete;

 private:
  bool& flag_;
};

/// Rounds run one after another in one handler before the event loop gets a turn (other
/// sessions, control requests): enough to amortise the turn, few enough to stay responsive.
constexpr int kRoundsPerTurn = 64;

}  // namespace

TimeConductor::TimeConductor(asio::io_context& io, GrantedScheduler& scheduler, broker::Broker& broker,
                             TimeConductorOptions options)
    : io_(io),
      scheduler_(scheduler),
      broker_(broker),
      options_(options),
      grace_timer_(io),
      pace_timer_(io),
      join_timer_(io) {
  // A reactor answers a boot-up at once, a heartbeat never (it only watches it): heartbeats on
  // those identifiers are passive for as long as a simulation runs.
  constexpr Duration kNever = std::chrono::hours(24 * 365);
  std::vector<std::uint32_t> boot_ups, both;
  std::vector<Acceptance::Passive> heartbeats;
  for (std::uint32_t id = 1; id <= 0x7F; ++id) {
    boot_ups.push_back(0x700 + id);
    heartbeats.push_back({0x700 + id, kNever});
  }
  both = boot_ups;
  for (std::uint32_t id = 1; id <= 0x7F; ++id)
    both.push_back(0x580 + id);
  boot_ups_.Set(false, boot_ups, heartbeats);
  boot_ups_and_answers_.Set(false, both, heartbeats);
}

std::uint64_t TimeConductor::AddReactor(std::string bus, std::function<Reaction()> reaction) {
  reactors_.push_back({next_reactor_, std::move(bus), std::move(reaction), {}});
  return next_reactor_++;
}

void TimeConductor::RemoveReactor(std::uint64_t id) {
  std::erase_if(reactors_, [id](const Reactor& r) { return r.id == id; });
}

TimeConductor::~TimeConductor() {
  alive_.reset();
  grace_timer_.cancel();
  pace_timer_.cancel();
  join_timer_.cancel();
}

void TimeConductor::Join(GrantedSession& session, const std::string& clock_id, std::uint64_t attachment,
                         std::uint32_t clock_ports) {
  Participant& p = participants_[clock_id];
  p.clock_id = clock_id;
  p.sessions.push_back(&session);
  p.ports = std::max<std::size_t>(clock_ports, 1);
  p.reached = std::max(p.reached, Now());
  MarkPending(p);  // it may act now (boot-up): it takes part in the next round
  sessions_[&session] = SessionState{&p, attachment, false};
  spdlog::debug("virtual time: {} joined at {} ({})", session.Label(), TimeText(Now()), clock_id);
  // A process counts once every port it attaches has joined: it powers on when its last port is
  // connected, and time started by its first port would run on (to a scenario's timeout, at the
  // speed of the broker alone) while the others are still on their way.
  if (const auto it = awaited_.find(clock_id); it != awaited_.end() && p.sessions.size() >= p.ports) {
    spdlog::debug("virtual time: {} joined; time goes on at {}", clock_id, TimeText(Now()));
    StopWaitingFor(clock_id);
  }
  if (join_target_ && JoinedProcesses() >= *join_target_) {
    spdlog::info("virtual time: {} node process(es) joined; time starts at {}", JoinedProcesses(),
                 TimeText(Now()));
    join_target_.reset();
    join_timer_.cancel();
    Release();
  }
  Kick();
}

void TimeConductor::Leave(GrantedSession& session) {
  auto it = sessions_.find(&session);
  if (it == sessions_.end()) return;
  Participant* p = it->second.participant;
  const bool was_granted = it->second.granted;
  sessions_.erase(it);
  std::erase(p->sessions, &session);
  if (!advancing_) Prune();
  if (was_granted && --outstanding_ == 0 && round_open_) {
    // Not from inside the session's own Close: close the round from the event loop.
    asio::post(io_, [this, alive = std::weak_ptr<int>(alive_)] {
      if (!alive.expired() && round_open_ && outstanding_ == 0) CloseRound();
    });
  }
}

void TimeConductor::Prune() {
  for (auto it = participants_.begin(); it != participants_.end();) {
    if (!it->second.sessions.empty()) {
      ++it;
      continue;
    }
    const Participant* gone = &it->second;
    std::erase_if(submissions_, [gone](const Submission& s) { return s.participant == gone; });
    if (gone->pending) --pending_count_;
    it = participants_.erase(it);
  }
}

void TimeConductor::Pending(GrantedSession& session, Duration reacts_after) {
  auto it = sessions_.find(&session);
  if (it == sessions_.end()) return;
  MarkPending(*it->second.participant, reacts_after);
  Kick();
}

void TimeConductor::MarkPending(Participant& p, Duration reacts_after) {
  if (Now() < p.reached) {
    // Per-node lookahead granted it past this: the premise of its horizon did not hold (a node's
    // timer sent what it had not said). It gets it at its own time, later than on the bus.
    ++stats_.causality_errors;
    if (!causality_logged_) {
      causality_logged_ = true;
      spdlog::error(
          "virtual time: something reached {} at {}, which had been granted to {} (a broken premise of "
          "per-node lookahead; grant_horizon.hpp)",
          p.clock_id, TimeText(Now()), TimeText(p.reached));
    }
  }
  if (p.pending) {
    p.reacts_after = std::min(p.reacts_after, reacts_after);
    return;
  }
  p.pending = true;
  p.reacts_after = reacts_after;
  ++pending_count_;
}

void TimeConductor::Submit(GrantedSession& session, broker::PortId port,
                           std::span<const wire::StampedFrame> frames) {
  auto it = sessions_.find(&session);
  if (it == sessions_.end()) return;
  for (const wire::StampedFrame& f : frames) {
    submissions_.push_back(
        {TimePoint(f.time), it->second.participant, &session.Bus(), next_sequence_++, port, f.frame});
  }
}

bool TimeConductor::Reached(GrantedSession& session, TimePoint time, std::optional<TimePoint> next_deadline,
                            const SendOutlook* outlook) {
  auto it = sessions_.find(&session);
  if (it == sessions_.end() || !it->second.granted || !round_open_) return false;
  SessionState& state = it->second;
  // A long grant may end early, at the instant after which the node's filter changed.
  const bool early = state.until - state.now > kLookahead && time >= state.now && time < state.until;
  if (time != state.until && !early) return false;
  state.granted = false;
  Participant& p = *state.participant;
  if (early && time != state.until) ++stats_.early_stops;
  p.reached = std::max(p.reached, time);
  p.next = next_deadline;
  p.has_outlook = outlook != nullptr;
  if (outlook != nullptr) {
    p.outlook.any = outlook->any;
    p.outlook.confined.assign(outlook->confined.begin(), outlook->confined.end());
  }
  if (--outstanding_ == 0 && !granting_) CloseRound();  // while granting, OpenRound closes it
  return true;
}

void TimeConductor::AtBoundary(std::function<void()> action) {
  if (!round_open_ && !advancing_ && CaughtUp()) {
    action();
    Kick();
    return;
  }
  boundary_.push_back(std::move(action));
  Kick();  // processes may stand ahead of the bus: rounds bring it up to them
}

void TimeConductor::Hold() {
  ++holds_;
}

void TimeConductor::Release() {
  if (holds_ > 0 && --holds_ == 0) Kick();
}

void TimeConductor::Drive() {
  ++drives_;
}

void TimeConductor::Undrive() {
  if (drives_ > 0 && --drives_ == 0) {
    if (advance_done_) FinishAdvance();
    Kick();
  }
}

void TimeConductor::Advance(TimePoint until, std::function<void(bool woken)> done) {
  if (drives_ == 0) throw std::logic_error("time is not driven: it runs on its own");
  if (advance_done_) throw std::logic_error("an advance is already running");
  advance_until_ = until;
  advance_woken_ = false;
  advance_done_ = std::move(done);
  Kick();
}

bool TimeConductor::AdvanceStops() {
  if (!advance_done_) return true;
  if (!advance_woken_ && Now() < advance_until_) return false;
  FinishAdvance();
  return true;
}

void TimeConductor::FinishAdvance() {
  auto done = std::move(advance_done_);
  advance_done_ = nullptr;
  const bool woken = advance_woken_;
  advance_woken_ = false;
  run_wall_start_.reset();  // time stands still until the next Advance: pacing starts again then
  if (done) done(woken);
}

std::size_t TimeConductor::JoinedProcesses() const {
  return static_cast<std::size_t>(std::ranges::count_if(
      participants_, [](const auto& entry) { return entry.second.sessions.size() >= entry.second.ports; }));
}

void TimeConductor::HoldUntilJoined(std::size_t processes, std::chrono::milliseconds timeout) {
  if (processes == 0 || JoinedProcesses() >= processes) return;
  Hold();
  join_target_ = processes;
  join_timer_.expires_after(timeout);
  join_timer_.async_wait([this, alive = std::weak_ptr<int>(alive_), timeout](const asio::error_code& ec) {
    if (ec || alive.expired() || !join_target_) return;
    spdlog::warn(
        "virtual time: {} of {} node processes joined on all their ports within {} ms (real time); time "
        "starts anyway",
        JoinedProcesses(), *join_target_, timeout.count());
    join_target_.reset();
    Release();
  });
}

void TimeConductor::HoldUntilProcessJoins(const std::string& clock_id, std::chrono::milliseconds timeout) {
  if (awaited_.contains(clock_id)) return;
  if (const auto it = participants_.find(clock_id);
      it != participants_.end() && it->second.sessions.size() >= it->second.ports)
    return;  // joined already
  Hold();
  auto timer = std::make_unique<asio::steady_timer>(io_, timeout);
  timer->async_wait(
      [this, alive = std::weak_ptr<int>(alive_), clock_id, timeout](const asio::error_code& ec) {
        if (ec || alive.expired() || !awaited_.contains(clock_id)) return;
        spdlog::warn("virtual time: {} did not join within {} ms (real time); time goes on", clock_id,
                     timeout.count());
        StopWaitingFor(clock_id);
      });
  awaited_.emplace(clock_id, std::move(timer));
}

void TimeConductor::StopWaitingFor(const std::string& clock_id) {
  const auto it = awaited_.find(clock_id);
  if (it == awaited_.end()) return;
  it->second->cancel();
  awaited_.erase(it);
  Release();
}

double TimeConductor::Factor() const {
  const double wall = std::chrono::duration<double>(stats_.wall).count();
  return wall > 0 ? std::chrono::duration<double>(stats_.simulated).count() / wall : 0.0;
}

void TimeConductor::Kick() {
  if (round_open_ || advancing_ || start_posted_ || pacing_) return;
  start_posted_ = true;
  asio::post(io_, [this, alive = std::weak_ptr<int>(alive_)] {
    if (alive.expired()) return;
    start_posted_ = false;
    StartRound();
  });
}

void TimeConductor::RunBoundaryActions() {
  while (!boundary_.empty()) {
    auto action = std::move(boundary_.front());
    boundary_.pop_front();
    action();
  }
}

void TimeConductor::StartRound() {
  for (int i = 0; i < kRoundsPerTurn; ++i) {
    if (round_open_ || advancing_) return;
    if (CaughtUp()) RunBoundaryActions();  // else when the bus has caught up with the processes
    if (!OpenRound()) return;
    if (round_open_) return;  // waiting for TimeReached; CloseRound kicks the next one
  }
  Kick();  // rounds without node processes: let the event loop have a turn
}

bool TimeConductor::OpenRound() {
  const TimePoint now = Now();
  // Broker timers armed at the current time (a frame submitted between rounds) run first.
  if (auto b = scheduler_.NextDeadline(); b && *b <= now) AdvanceBroker(now);
  // Per-node lookahead; also to bring the bus up to processes granted ahead of it before time is
  // driven or paced with one G for all.
  if (PerNode() || !CaughtUp()) return OpenPerNodeRound(now);
  per_node_round_ = false;

  std::optional<TimePoint> node_next;
  for (const auto& [id, p] : participants_) {
    std::optional<TimePoint> t = p.pending ? std::optional(now) : p.next;
    if (t && (!node_next || *t < *node_next)) node_next = t;
  }
  const std::optional<TimePoint> broker_next = scheduler_.NextDeadline();
  if (holds_ == 0 && drives_ > 0) {
    if (AdvanceStops()) return false;
    if (!node_next && !broker_next) {
      // Nothing happens before the step's end: the fleet is there at once.
      scheduler_.AdvanceTo(advance_until_);
      FinishAdvance();
      return false;
    }
  }
  if (holds_ > 0 || (participants_.empty() && drives_ == 0) || (!node_next && !broker_next)) {
    run_wall_start_.reset();  // time stands still: pacing and the factor start again
    return false;
  }
  TimePoint until = broker_next ? *broker_next : TimePoint::max();
  if (node_next) until = std::min(until, *node_next + kLookahead);
  if (drives_ > 0) until = std::min(until, advance_until_);
  if (until <= now) until = now + Duration(1);

  const auto wall_now = std::chrono::steady_clock::now();
  if (!run_wall_start_) {
    run_wall_start_ = wall_now;
    run_sim_start_ = now;
    last_wall_ = wall_now;
  }
  if (options_.speed > 0) {
    const auto due =
        *run_wall_start_ +
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(
            std::chrono::duration<double>(until - run_sim_start_).count() / options_.speed));
    if (due > wall_now) {
      pacing_ = true;
      pace_timer_.expires_at(due);
      pace_timer_.async_wait([this, alive = std::weak_ptr<int>(alive_)](const asio::error_code& ec) {
        if (ec || alive.expired()) return;
        pacing_ = false;
        StartRound();  // the wait counts as real time: the factor is then the pace achieved
      });
      return false;
    }
  }

  round_open_ = true;
  round_until_ = until;
  outstanding_ = 0;
  for (auto& [id, p] : participants_)
    if (p.pending || (p.next && *p.next <= until)) MarkGranted(p, now, until);
  return SendGrants();
}

void TimeConductor::MarkGranted(Participant& p, TimePoint now, TimePoint until) {
  if (p.pending) --pending_count_;
  p.pending = false;
  for (GrantedSession* s : p.sessions) {
    SessionState& state = sessions_[s];
    state.granted = true;
    state.now = now;
    state.until = until;
    ++outstanding_;
  }
}

TimePoint TimeConductor::Frontier() const {
  TimePoint furthest = Now();
  for (const auto& [id, p] : participants_)
    furthest = std::max(furthest, p.reached);
  return furthest;
}

void TimeConductor::ComputeHorizons(TimePoint now, std::optional<TimePoint> cap) {
  order_.clear();
  nodes_.clear();
  std::fill(bus_sessions_.begin(), bus_sessions_.end(), 0);
  std::fill(anything_.begin(), anything_.end(), false);
  const auto bus_index = [this](const std::string& name) {
    auto it = std::ranges::find(bus_names_, name);
    if (it == bus_names_.end()) {
      bus_names_ = broker_.Buses();  // a bus added since
      bus_sessions_.resize(bus_names_.size(), 0);
      anything_.resize(bus_names_.size(), false);
      it = std::ranges::find(bus_names_, name);
    }
    return static_cast<std::size_t>(it - bus_names_.begin());
  };
  for (auto& [id, p] : participants_) {
    p.ports_of_round.clear();
    for (const GrantedSession* session : p.sessions) {
      const std::size_t b = bus_index(session->Bus());
      if (b >= bus_names_.size()) continue;  // not a bus of this broker (cannot happen)
      p.ports_of_round.push_back({b, &session->Accepting()});
      ++bus_sessions_[b];
    }
    p.round_index = order_.size();
    order_.push_back(&p);
  }
  for (Reactor& r : reactors_) {
    r.ports.clear();
    const std::size_t b = bus_index(r.bus);
    if (b >= bus_names_.size()) continue;
    const Reaction reaction = r.reaction ? r.reaction() : Reaction::kAnything;
    if (reaction == Reaction::kAnything) anything_[b] = true;
    r.ports.push_back({b, reaction == Reaction::kBootUps ? &boot_ups_ : &boot_ups_and_answers_});
    ++bus_sessions_[b];
  }
  buses_.resize(bus_names_.size());
  for (std::size_t b = 0; b < bus_names_.size(); ++b) {
    broker_.Outlook(bus_names_[b], bus_outlook_);
    HorizonBus& bus = buses_[b];
    // Calm only if every port that may transmit is a node process's: anything else (a tool, the
    // fleet's own SDO client) may answer what it hears at once, which the horizons do not model.
    bus.calm = bus_outlook_.calm && bus_outlook_.transmitters == bus_sessions_[b] && !anything_[b];
    bus.next_event = bus_outlook_.next_event;
    bus.pending.clear();
    for (const CanFrame& f : bus_outlook_.frames)
      bus.pending.push_back({Acceptance::KeyOf(f), IsHeartbeat(f)});
  }
  for (const Participant* p : order_) {
    HorizonNode& node = nodes_.emplace_back();
    node.pending = p->pending;
    node.reacts_after = p->reacts_after;
    node.next = p->next;
    node.any = p->has_outlook ? p->outlook.any : p->next;
    if (p->has_outlook) node.confined = p->outlook.confined;
    node.ports = p->ports_of_round;
  }
  for (const Reactor& r : reactors_) {
    HorizonNode& node = nodes_.emplace_back();  // no timers of its own: it answers what it hears
    node.ports = r.ports;
  }
  // What the processes sent ahead of the bus, not on it yet.
  known_.clear();
  for (const Submission& s : submissions_) {
    const std::size_t b = bus_index(*s.bus_key);
    if (b >= bus_names_.size()) continue;
    known_.push_back(
        {b, s.participant->round_index, Acceptance::KeyOf(s.frame), s.time, IsHeartbeat(s.frame)});
  }
  horizons_.Compute(now, kLookahead, cap, buses_, nodes_, known_);
}

bool TimeConductor::OpenPerNodeRound(TimePoint now) {
  const bool catching_up = !CaughtUp();
  // Held, or an outside input waiting: time stands still once the bus has caught up with every
  // process (the input is applied then, at StartRound).
  if (((holds_ > 0 || !boundary_.empty()) && !catching_up) || participants_.empty()) {
    run_wall_start_.reset();
    return false;
  }
  // What the broker does on its own (a scenario step, a fault's timer) may reach anybody; a bus's
  // own timer is described by its outlook.
  scheduler_.TakeOutlook(broker_timers_);
  TimePoint cap = now + kMaxGrant;
  if (broker_timers_.unconfined) cap = std::min(cap, *broker_timers_.unconfined);
  if (holds_ > 0 || !boundary_.empty() || !PerNode()) cap = std::min(cap, Frontier());
  ComputeHorizons(now, cap);

  bool any_due = pending_count_ > 0;
  for (const Participant* p : order_)
    any_due = any_due || p->next.has_value();
  if (!any_due && !scheduler_.NextDeadline()) {
    run_wall_start_.reset();  // nothing will ever happen: time stands still
    if (catching_up) {
      // Nothing happens before the furthest process: the bus is there at once (outside inputs
      // wait for it).
      scheduler_.AdvanceTo(Frontier());
      Kick();
    }
    return false;
  }
  const auto wall_now = std::chrono::steady_clock::now();
  if (!run_wall_start_) {
    run_wall_start_ = wall_now;
    run_sim_start_ = now;
    last_wall_ = wall_now;
  }

  per_node_round_ = true;
  round_open_ = true;
  outstanding_ = 0;
  for (std::size_t i = 0; i < order_.size(); ++i) {
    Participant& p = *order_[i];
    const TimePoint horizon = std::min(horizons_.Of(i).value_or(cap), cap);
    if (!p.pending && !(p.next && *p.next <= horizon)) continue;  // nothing to do before its horizon
    TimePoint until = horizon <= now ? now + Duration(1) : horizon;
    if (until <= p.reached) {
      if (!p.pending) continue;  // it is there already
      until = p.reached;         // a causality error, counted when it became pending
    }
    MarkGranted(p, now, until);
  }
  return SendGrants();
}

bool TimeConductor::SendGrants() {
  // Granted after marking: a session failing in SendGrant leaves with its grant counted.
  std::vector<GrantedSession*> granted;
  for (auto& [s, state] : sessions_)
    if (state.granted) granted.push_back(const_cast<GrantedSession*>(s));
  std::sort(granted.begin(), granted.end(), [this](GrantedSession* a, GrantedSession* b) {
    const auto& pa = sessions_[a].participant->clock_id;
    const auto& pb = sessions_[b].participant->clock_id;
    return pa != pb ? pa < pb : a->Bus() < b->Bus();
  });
  stats_.grants += granted.size();
  granting_ = true;
  for (GrantedSession* s : granted) {
    auto it = sessions_.find(s);
    if (it == sessions_.end()) continue;  // left while an earlier grant was sent
    // Each grant names every session of its process granted with it (all of them): the process
    // reads its ports in no set order, and may read this grant before the HelloReply of another
    // port joined before this round (orchestrator/broker/README.md "Virtual time",
    // VirtualTimeClient::RunIfAllGranted).
    attachments_.clear();
    for (const GrantedSession* sibling : it->second.participant->sessions)
      if (const std::uint64_t a = sessions_.at(sibling).attachment; a != 0) attachments_.push_back(a);
    s->SendGrant(it->second.now, it->second.until, attachments_);
  }
  granting_ = false;
  if (outstanding_ == 0) {
    CloseRound();
    return true;
  }
  // One OS timer for many rounds: armed only when none is pending (re-arming it for every round
  // of a few microseconds cost two timerfd syscalls each); it checks the open round's age.
  round_opened_ = std::chrono::steady_clock::now();
  if (!grace_armed_) ArmGrace(round_opened_ + options_.grace);
  return true;
}

void TimeConductor::ArmGrace(std::chrono::steady_clock::time_point at) {
  grace_armed_ = true;
  grace_timer_.expires_at(at);
  grace_timer_.async_wait([this, alive = std::weak_ptr<int>(alive_)](const asio::error_code& ec) {
    if (ec || alive.expired()) return;
    grace_armed_ = false;
    if (!round_open_) return;  // the next round arms it again
    const auto due = round_opened_ + options_.grace;
    if (std::chrono::steady_clock::now() < due) {
      ArmGrace(due);  // a younger round than the one it was armed for
      return;
    }
    OnGraceExpired();
  });
}

void TimeConductor::CloseRound() {
  round_open_ = false;
  if (per_node_round_) {
    // The bus runs up to the earliest deadline of any process: until then none sends anything it
    // has not sent already, unless something reaches it first (then the bus stops there).
    std::optional<TimePoint> earliest;  // of any process
    for (const auto& [id, p] : participants_) {
      if (p.pending) earliest = Now();
      if (p.next && (!earliest || *p.next < *earliest)) earliest = *p.next;
    }
    // No process has anything to do: the bus runs to its own next event, or up to the furthest
    // process; time does not run on for nothing.
    TimePoint target = earliest ? *earliest : std::max(Frontier(), scheduler_.NextDeadline().value_or(Now()));
    target = std::min(target, Now() + kMaxGrant);
    if (holds_ > 0 || !boundary_.empty() || !PerNode())
      target = std::min(target, std::max(Frontier(), Now()));
    AdvanceBrokerUntilInput(std::max(target, Now()));
  } else {
    AdvanceBroker(round_until_);
  }
  ++stats_.rounds;
  const auto wall_now = std::chrono::steady_clock::now();
  stats_.wall += wall_now - last_wall_;
  last_wall_ = wall_now;
  Kick();
}

void TimeConductor::AdvanceBroker(TimePoint until) {
  const FlagScope advancing(advancing_);
  const TimePoint start = Now();
  SortSubmissions();
  std::size_t taken = 0;
  for (; taken < submissions_.size() && submissions_[taken].time <= until; ++taken) {
    PutOnBus(submissions_[taken]);
  }
  submissions_.erase(submissions_.begin(), submissions_.begin() + static_cast<std::ptrdiff_t>(taken));
  scheduler_.AdvanceTo(until);
  stats_.simulated += Now() - start;
  Prune();  // processes that left meanwhile
}

void TimeConductor::PutOnBus(const Submission& s) {
  if (s.time < Now()) ++stats_.late_frames;
  scheduler_.AdvanceTo(s.time);  // the broker's timers due by then first; a time in the past is now
  broker_.Submit(s.port, s.frame);
  ++stats_.frames;
}

void TimeConductor::SortSubmissions() {
  // The tie rule for frames stamped at one instant: by process name, bus, then the order sent.
  std::stable_sort(submissions_.begin(), submissions_.end(), [](const Submission& a, const Submission& b) {
    if (a.time != b.time) return a.time < b.time;
    if (a.participant != b.participant) return a.participant->clock_id < b.participant->clock_id;
    if (*a.bus_key != *b.bus_key) return *a.bus_key < *b.bus_key;
    return a.sequence < b.sequence;
  });
}

void TimeConductor::AdvanceBrokerUntilInput(TimePoint until) {
  const FlagScope advancing(advancing_);
  const TimePoint start = Now();
  const int holds_at_start = holds_;
  SortSubmissions();
  // Instant by instant, in the order AdvanceBroker takes them (each frame after the timers due by
  // its time), so that the bus is the same whichever way it was granted.
  std::size_t taken = 0;
  bool stopped = false;
  for (;;) {
    std::optional<TimePoint> instant = scheduler_.NextDeadline();
    if (taken < submissions_.size() && (!instant || submissions_[taken].time < *instant))
      instant = std::max(submissions_[taken].time, Now());
    if (!instant || *instant > until) break;
    if (*instant > Now() && (pending_count_ > 0 || holds_ > holds_at_start)) {
      stopped = true;  // something reached a process (or a hold began) at Now(): it acts there first
      break;
    }
    for (; taken < submissions_.size() && submissions_[taken].time <= *instant; ++taken) {
      PutOnBus(submissions_[taken]);
    }
    scheduler_.AdvanceTo(*instant);
  }
  submissions_.erase(submissions_.begin(), submissions_.begin() + static_cast<std::ptrdiff_t>(taken));
  if (!stopped && pending_count_ == 0 && holds_ <= holds_at_start) scheduler_.AdvanceTo(until);
  stats_.simulated += Now() - start;
  Prune();
}

void TimeConductor::OnGraceExpired() {
  if (!round_open_) return;
  std::vector<GrantedSession*> late;
  for (auto& [s, state] : sessions_)
    if (state.granted) late.push_back(const_cast<GrantedSession*>(s));
  for (GrantedSession* s : late) {
    ++stats_.evictions;
    s->Evict("no TimeReached within " + std::to_string(options_.grace.count()) +
             " ms (real time) of the grant to " + TimeText(round_until_) +
             ": treated as disconnected, the bus's time goes on");
  }
}

}  // namespace canfleet::transport
