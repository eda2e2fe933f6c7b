#pragma once
/// @file Helpers for the broker tests: a sink that records what a port receives (frames in candump
/// notation with their bus times, TX confirmations, controller events) and a scheduler whose
/// timers fire late, as a real-time driver's do when the event loop is busy.

#include <chrono>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "bus/physics/frame_timing.hpp"
#include "clock/scheduler.hpp"
#include "orchestrator/broker/broker.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::broker::test {

using canfleet::test::Frame;
using namespace std::chrono_literals;

/// "123#01@330000": a frame and its time in nanoseconds, so expectations read as a bus script.
inline std::string At(const TimedFrame& f) {
  return ToCandump(f.frame) + (f.frame.error() ? "!" : "") + "@" + std::to_string(f.time.count());
}
inline std::string At(std::string_view frame, BusTime time) {
  return std::string(frame) + "@" + std::to_string(time.count());
}

/// Bus occupancy of a successful transfer of `text` at `bitrate`, via bus/physics/frame_timing.hpp.
inline BusTime FrameTime(std::string_view text, std::uint32_t bitrate) {
  return BitTime(CountFrameBits(Frame(text)).total(), bitrate);
}
/// SOF .. end of CRC, stuff bits included.
inline std::uint32_t StuffedBits(std::string_view text) {
  const FrameBits bits = CountFrameBits(Frame(text));
  return bits.unstuffed + bits.stuff;
}

class RecordingSink : public PortSink {
 public:
  explicit RecordingSink(const Scheduler* scheduler = nullptr) : scheduler_(scheduler) {}

  void Deliver(std::span<const TimedFrame> batch) override {
    ++deliver_calls;
    for (const auto& f : batch) {
      frames.push_back(f);
      log.push_back("rx " + At(f));
    }
    if (on_deliver) on_deliver(batch);
  }
  void TxConfirmed(std::span<const TimedFrame> batch) override {
    ++confirm_calls;
    for (const auto& f : batch) {
      confirmed.push_back(f);
      log.push_back("tx " + At(f));
    }
    if (on_confirm) on_confirm(batch);
  }
  void ControllerChanged(const ControllerEvent& event) override {
    events.push_back(event);
    event_times.push_back(scheduler_ != nullptr ? scheduler_->Now().time_since_epoch() : BusTime{});
    log.push_back(std::string(ToString(event.state)) + " tec=" + std::to_string(event.tec) +
                  " rec=" + std::to_string(event.rec));
    if (on_event) on_event(event);
  }

  /// Received frames as "id#data@ns".
  std::vector<std::string> Received() const {
    std::vector<std::string> out;
    for (const auto& f : frames)
      out.push_back(At(f));
    return out;
  }
  /// Received frames in candump notation only.
  std::vector<std::string> Ids() const {
    std::vector<std::string> out;
    for (const auto& f : frames)
      out.push_back(ToCandump(f.frame));
    return out;
  }
  std::vector<std::string> Confirmed() const {
    std::vector<std::string> out;
    for (const auto& f : confirmed)
      out.push_back(At(f));
    return out;
  }
  std::vector<ControllerState> States() const {
    std::vector<ControllerState> out;
    for (const auto& e : events)
      out.push_back(e.state);
    return out;
  }

  std::vector<TimedFrame> frames;
  std::vector<TimedFrame> confirmed;
  std::vector<ControllerEvent> events;
  std::vector<BusTime> event_times;  ///< scheduler time of each event (simulated time: exact)
  std::vector<std::string> log;      ///< every callback in order
  int deliver_calls = 0;
  int confirm_calls = 0;
  std::function<void(std::span<const TimedFrame>)> on_deliver;
  std::function<void(std::span<const TimedFrame>)> on_confirm;
  std::function<void(const ControllerEvent&)> on_event;

 private:
  const Scheduler* scheduler_;
};

/// Time as a real-time driver sees it: time passes (SetNow) while the event loop is busy, then
/// the loop wakes (Wake) and every timer due by then runs with Now() = the wake-up time.
class LateScheduler final : public Scheduler {
 public:
  TimePoint Now() const override { return now_; }
  void SetNow(TimePoint t) { now_ = t; }
  void Wake() { RunDue(now_, nullptr); }
  void JumpTo(TimePoint t) {
    SetNow(t);
    Wake();
  }

 private:
  TimePoint now_{};
};

inline TimePoint T(BusTime t) {
  return TimePoint(t);
}

}  // namespace canfleet::broker::test
