#include "clock/scheduler.hpp"

#include <cassert>
#include <utility>

namespace canfleet {

Scheduler::~Scheduler() {
  // Timers must not outlive their scheduler; detach any left so their destructors are harmless.
  for (Timer* t : heap_)
    t->heap_index_ = Timer::kNotArmed;
}

std::optional<TimePoint> Scheduler::NextDeadline() const {
  if (heap_.empty()) return std::nullopt;
  return heap_.front()->deadline_;
}

void Scheduler::RunDue(TimePoint limit, const std::function<void(TimePoint)>& on_each) {
  while (!heap_.empty() && heap_.front()->deadline_ <= limit) {
    Timer* t = heap_.front();
    Disarm(*t);
    if (on_each) on_each(t->deadline_);
    t->on_expiry_();  // may re-arm t or touch other timers; the heap is consistent here
  }
}

bool Scheduler::Before(const Timer* a, const Timer* b) const {
  if (a->deadline_ != b->deadline_) return a->deadline_ < b->deadline_;
  return a->sequence_ < b->sequence_;
}

void Scheduler::Swap(std::size_t i, std::size_t j) {
  std::swap(heap_[i], heap_[j]);
  heap_[i]->heap_index_ = i;
  heap_[j]->heap_index_ = j;
}

void Scheduler::SiftUp(std::size_t i) {
  while (i > 0) {
    std::size_t parent = (i - 1) / 2;
    if (!Before(heap_[i], heap_[parent])) break;
    Swap(i, parent);
    i = parent;
  }
}

void Scheduler::SiftDown(std::size_t i) {
  for (;;) {
    std::size_t smallest = i;
    for (std::size_t child : {2 * i + 1, 2 * i + 2}) {
      if (child < heap_.size() && Before(heap_[child], heap_[smallest])) smallest = child;
    }
    if (smallest == i) return;
    Swap(i, smallest);
    i = smallest;
  }
}

void Scheduler::Arm(Timer& timer, TimePoint deadline) {
  auto old_front = heap_.empty() ? nullptr : heap_.front();
  auto old_deadline = old_front ? old_front->deadline_ : TimePoint{};
  timer.deadline_ = deadline;
  timer.sequence_ = next_sequence_++;
  if (timer.heap_index_ == Timer::kNotArmed) {
    timer.heap_index_ = heap_.size();
    heap_.push_back(&timer);
    SiftUp(timer.heap_index_);
  } else {
    SiftUp(timer.heap_index_);
    SiftDown(timer.heap_index_);
  }
  if (heap_.front() != old_front || heap_.front()->deadline_ != old_deadline) OnNextDeadlineChanged();
}

void Scheduler::Disarm(Timer& timer) {
  std::size_t i = timer.heap_index_;
  if (i == Timer::kNotArmed) return;
  bool was_front = i == 0;
  std::size_t last = heap_.size() - 1;
  if (i != last) Swap(i, last);
  heap_.pop_back();
  timer.heap_index_ = Timer::kNotArmed;
  if (i < heap_.size()) {
    Timer* moved = heap_[i];
    SiftUp(i);
    SiftDown(moved->heap_index_);
  }
  if (was_front) OnNextDeadlineChanged();
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
  scheduler_.Disarm(*this);
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
