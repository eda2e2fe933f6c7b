#pragma once
/// @file Where scheduler time meets the wall clock, once for the whole process: capture files and
/// socketcand clients stamp frames with wall-clock times, the broker and every timer run on
/// scheduler time. An edge of the system: protocol code never reads the system clock.

#include <chrono>

#include "clock/scheduler.hpp"

namespace canfleet {

/// Wall-clock time (Unix epoch) with nanoseconds, as capture files and socketcand clients expect it.
using WallTime = std::chrono::sys_time<std::chrono::nanoseconds>;

/// The wall-clock time of the scheduler's time 0, read from the system clock now: bus times
/// (scheduler time) + this origin = wall-clock times. Read it once per process and hand it to
/// everything that stamps frames, so that a capture and a socketcand client agree to the
/// nanosecond on when a frame was on the bus.
WallTime WallClockOrigin(const Scheduler& scheduler);

}  // namespace canfleet
