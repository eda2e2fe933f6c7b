#include "clock/scheduler.hpp"

#include <algorithm>
#include <cassert>
#include <limits>
#include <utility>

namespace canfleet {

Scheduler::~Scheduler() {
  // Timers must not outlive their scheduler; detach any left so their destructors are harmless.
  for (Timer* t : heap_)
    t->heap_index_ = Timer::kNotArmed;
  for (Timer* t : sleeping_) {
    t->heap_index_ = Timer::kNotArmed;
    t->sleep_period_ = Duration::zero();
  }
}

std::optional<TimePoint> Scheduler::NextDeadline() const {
  if (heap_.empty()) return std::nullopt;
  return heap_.front()->deadline_;
}

void Scheduler::RunDue(TimePoint limit, const std::function<void(TimePoint)>& on_each) {
  struct Running {
    bool& flag;
    explicit Running(bool& f) : flag(f) { flag = true; }
    ~Running() { flag = false; }
  } running(running_due_);
  for (;;) {
    if (heap_.empty() || heap_.front()->deadline_ > limit) {
      AdvanceSleepers(limit, std::numeric_limits<std::uint64_t>::max());
      return;
    }
    Timer* t = heap_.front();
    AdvanceSleepers(t->deadline_, t->sequence_);  // touches sleeping_ only: t is still the front
    Disarm(*t);
    if (on_each) on_each(t->deadline_);
    ++fired_;
    struct Confined {
      std::uint32_t& running;
      ~Confined() { running = Timer::kUnconfined; }
    } confined{running_confinement_};
    running_confinement_ = t->confinement_;
    t->on_expiry_();  // may re-arm t or touch other timers; the heap is consistent here
  }
}

// Each sleeping timer stands for a callback that re-arms itself one period on and does nothing
// else. Taking the sleepers in (deadline, sequence) order, each re-arm gets the next sequence
// number, so ties at a later instant break exactly as they would have. A sleeper's firings before
// the next event (the next other sleeper or the bound) are consecutive: they go in one step.
void Scheduler::AdvanceSleepers(TimePoint deadline, std::uint64_t sequence) {
  while (!sleeping_.empty()) {
    Timer* t = sleeping_.front();
    if (t->deadline_ > deadline || (t->deadline_ == deadline && t->sequence_ >= sequence)) return;
    TimePoint bound = deadline;
    for (std::size_t child : {std::size_t{1}, std::size_t{2}}) {
      if (child < sleeping_.size()) bound = std::min(bound, sleeping_[child]->deadline_);
    }
    const auto period = t->sleep_period_.count();
    std::int64_t steps = 1;  // at the bound itself (a tie), one firing at a time
    if (t->deadline_ < bound) steps = ((bound - t->deadline_).count() + period - 1) / period;
    t->deadline_ += Duration(steps * period);
    t->sequence_ = next_sequence_++;
    SiftDown(sleeping_, 0);
  }
}

void Scheduler::CatchUpSleepers() {
  if (!running_due_ && !sleeping_.empty()) AdvanceSleepers(Now(), std::numeric_limits<std::uint64_t>::max());
}

bool Scheduler::Before(const Timer* a, const Timer* b) {
  if (a->deadline_ != b->deadline_) return a->deadline_ < b->deadline_;
  return a->sequence_ < b->sequence_;
}

void Scheduler::Swap(Heap& heap, std::size_t i, std::size_t j) {
  std::swap(heap[i], heap[j]);
  heap[i]->heap_index_ = i;
  heap[j]->heap_index_ = j;
}

void Scheduler::SiftUp(Heap& heap, std::size_t i) {
  while (i > 0) {
    std::size_t parent = (i - 1) / 2;
    if (!Before(heap[i], heap[parent])) break;
    Swap(heap, i, parent);
    i = parent;
  }
}

void Scheduler::SiftDown(Heap& heap, std::size_t i) {
  for (;;) {
    std::size_t smallest = i;
    for (std::size_t child : {2 * i + 1, 2 * i + 2}) {
      if (child < heap.size() && Before(heap[child], heap[smallest])) smallest = child;
    }
    if (smallest == i) return;
    Swap(heap, i, smallest);
    i = smallest;
  }
}

void Scheduler::Insert(Heap& heap, Timer& timer) {
  timer.heap_index_ = heap.size();
  heap.push_back(&timer);
  SiftUp(heap, timer.heap_index_);
}

void Scheduler::Remove(Heap& heap, Timer& timer) {
  std::size_t i = timer.heap_index_;
  std::size_t last = heap.size() - 1;
  if (i != last) Swap(heap, i, last);
  heap.pop_back();
  timer.heap_index_ = Timer::kNotArmed;
  if (i < heap.size()) {
    Timer* moved = heap[i];
    SiftUp(heap, i);
    SiftDown(heap, moved->heap_index_);
  }
}

void Scheduler::TakeOutlook(TimerOutlook& out) const {
  out.unconfined.reset();
  out.confined.clear();
  for (const Timer* t : heap_) {
    if (t->confinement_ == Timer::kUnconfined) {
      if (!out.unconfined || t->deadline_ < *out.unconfined) out.unconfined = t->deadline_;
      continue;
    }
    auto it = std::lower_bound(out.confined.begin(), out.confined.end(), t->confinement_,
                               [](const auto& entry, std::uint32_t key) { return entry.first < key; });
    if (it != out.confined.end() && it->first == t->confinement_)
      it->second = std::min(it->second, t->deadline_);
    else
      out.confined.insert(it, {t->confinement_, t->deadline_});
  }
}

void Scheduler::Arm(Timer& timer, TimePoint deadline) {
  if (running_confinement_ != Timer::kUnconfined && timer.confinement_ != running_confinement_)
    ++confinement_breaches_;
  if (timer.Asleep()) {
    Remove(sleeping_, timer);
    timer.sleep_period_ = Duration::zero();
  }
  CatchUpSleepers();  // what slept until now came first: it is ordered before this arming
  auto old_front = heap_.empty() ? nullptr : heap_.front();
  auto old_deadline = old_front ? old_front->deadline_ : TimePoint{};
  timer.deadline_ = deadline;
  timer.sequence_ = next_sequence_++;
  if (timer.heap_index_ == Timer::kNotArmed) {
    Insert(heap_, timer);
  } else {
    SiftUp(heap_, timer.heap_index_);
    SiftDown(heap_, timer.heap_index_);
  }
  if (heap_.front() != old_front || heap_.front()->deadline_ != old_deadline) OnNextDeadlineChanged();
}

void Scheduler::Disarm(Timer& timer) {
  if (timer.heap_index_ == Timer::kNotArmed) return;
  if (timer.Asleep()) {
    Remove(sleeping_, timer);
    timer.sleep_period_ = Duration::zero();
    return;
  }
  bool was_front = timer.heap_index_ == 0;
  Remove(heap_, timer);
  if (was_front) OnNextDeadlineChanged();
}

void Scheduler::Sleep(Timer& timer, Duration period) {
  assert(period > Duration::zero());
  if (timer.heap_index_ == Timer::kNotArmed || period <= Duration::zero()) return;
  if (timer.Asleep()) {
    timer.sleep_period_ = period;
    return;
  }
  bool was_front = timer.heap_index_ == 0;
  Remove(heap_, timer);
  timer.sleep_period_ = period;
  Insert(sleeping_, timer);  // keeps its deadline and sequence: its place in the order
  if (was_front) OnNextDeadlineChanged();
}

void Scheduler::Wake(Timer& timer) {
  if (!timer.Asleep()) return;
  if (running_confinement_ != Timer::kUnconfined && timer.confinement_ != running_confinement_)
    ++confinement_breaches_;
  CatchUpSleepers();
  Remove(sleeping_, timer);
  timer.sleep_period_ = Duration::zero();
  auto old_front = heap_.empty() ? nullptr : heap_.front();
  auto old_deadline = old_front ? old_front->deadline_ : TimePoint{};
  Insert(heap_, timer);  // the deadline and sequence it reached asleep
  if (heap_.front() != old_front || heap_.front()->deadline_ != old_deadline) OnNextDeadlineChanged();
}

Timer::Timer(Scheduler& scheduler, std::function<void()> on_expiry)
    : scheduler_(scheduler), on_expiry_(std::move(on_expiry)) {
  assert(on_expiry_);
}

Timer::~Timer() {
  Cancel();
}

void Timer::StartAt(TimePoint deadline) {
  scheduler_.Arm(*this, deadline);
}
void Timer::StartAfter(Duration delay) {
  StartAt(scheduler_.Now() + delay);
}
void Timer::Cancel() {
  // A timer that is not armed never touches its scheduler, so one may be destroyed (or cancelled)
  // after the scheduler it was made with, as long as it is not armed then.
  if (heap_index_ == kNotArmed) return;
  scheduler_.Disarm(*this);
}
void Timer::Sleep(Duration period) {
  scheduler_.Sleep(*this, period);
}
void Timer::Wake() {
  scheduler_.Wake(*this);
}

void SimulatedScheduler::AdvanceTo(TimePoint t) {
  if (t < now_) t = now_;
  RunDue(t, [this](TimePoint deadline) {
    if (deadline > now_) now_ = deadline;
  });
  now_ = t;
}

TimePoint SimulatedScheduler::RunUntilIdle(Duration limit) {
  TimePoint end = now_ + limit;
  while (auto next = NextDeadline()) {
    if (*next > end) break;
    AdvanceTo(*next);
  }
  return now_;
}

}  // namespace canfleet
