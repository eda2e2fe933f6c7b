#pragma once
/// @file Durations as the CLI and the control API's messages write them: "500ms", "2s", "1.5s",
/// "1m", "2h". Millisecond resolution, as the control API's *_ms fields.

#include <chrono>
#include <optional>
#include <string>
#include <string_view>

namespace canfleet::control {

/// Parses a non-negative number (digits, optionally a decimal fraction) followed by a unit: ms,
/// s, m or h. Refuses a missing unit, a negative value, anything finer than 1 ms ("1.5ms") and
/// values beyond about 290 million years. On failure returns nullopt and, when `error` is given,
/// says why in one line: `duration "5": missing unit (e.g. 500ms, 2s, 1.5s, 1m)`.
std::optional<std::chrono::milliseconds> ParseDuration(std::string_view text, std::string* error = nullptr);

/// The shortest text ParseDuration reads back to `d`: "0ms", "500ms", "2s", "1.5s", "90s", "1m",
/// "2h". Negative durations are written with a leading '-' (ParseDuration refuses them).
std::string FormatDuration(std::chrono::milliseconds d);

}  // namespace canfleet::control
