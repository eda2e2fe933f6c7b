// CLI durations (orchestrator/control/duration_text.hpp).
#include "orchestrator/control/duration_text.hpp"

#include <gtest/gtest.h>

namespace canfleet::control {
namespace {

using std::chrono::milliseconds;

TEST(Duration, UnitsAndFractions) {
  EXPECT_EQ(ParseDuration("500ms"), milliseconds(500));
  EXPECT_EQ(ParseDuration("2s"), milliseconds(2'000));
  EXPECT_EQ(ParseDuration("1.5s"), milliseconds(1'500));
  EXPECT_EQ(ParseDuration("0.001s"), milliseconds(1));
  EXPECT_EQ(ParseDuration("1m"), milliseconds(60'000));
  EXPECT_EQ(ParseDuration("1.5m"), milliseconds(90'000));
  EXPECT_EQ(ParseDuration("2h"), milliseconds(7'200'000));
  EXPECT_EQ(ParseDuration("0ms"), milliseconds(0));
  EXPECT_EQ(ParseDuration(".5s"), milliseconds(500));
  EXPECT_EQ(ParseDuration("1.500000000s"), milliseconds(1'500)) << "trailing zeros are not finer than 1 ms";
}

TEST(Duration, RefusalsSayWhy) {
  const std::pair<const char*, const char*> kBad[] = {
      {"5", "duration \"5\": missing unit (e.g. 500ms, 2s, 1.5s, 1m)"},
      {"", "duration \"\": expected a number and a unit (e.g. 500ms, 2s, 1.5s, 1m)"},
      {"ms", "duration \"ms\": expected a number and a unit (e.g. 500ms, 2s, 1.5s, 1m)"},
      {"-1s", "duration \"-1s\": must not be negative"},
      {"1.5ms", "duration \"1.5ms\": finer than 1 ms"},
      {"0.0001s", "duration \"0.0001s\": finer than 1 ms"},
      {"1.s", "duration \"1.s\": expected digits after '.'"},
      {"3d", "duration \"3d\": unknown unit \"d\" (ms, s, m or h)"},
      {"1 s", "duration \"1 s\": unknown unit \" s\" (ms, s, m or h)"},
      {"99999999999999999999s", "duration \"99999999999999999999s\": too long"},
  };
  for (const auto& [text, message] : kBad) {
    std::string error;
    EXPECT_FALSE(ParseDuration(text, &error).has_value()) << text;
    EXPECT_EQ(error, message);
  }
  EXPECT_FALSE(ParseDuration("x").has_value()) << "the error text is optional";
}

TEST(Duration, FormatIsTheShortestTextThatParsesBack) {
  const std::pair<long long, const char*> kCases[] = {
      {0, "0ms"},      {500, "500ms"}, {1'000, "1s"},   {1'500, "1.5s"},   {1'005, "1.005s"},
      {90'000, "90s"}, {60'000, "1m"}, {120'000, "2m"}, {3'600'000, "1h"}, {3'660'000, "61m"},
  };
  for (const auto& [ms, text] : kCases) {
    EXPECT_EQ(FormatDuration(milliseconds(ms)), text);
    EXPECT_EQ(ParseDuration(text), milliseconds(ms));
  }
}

}  // namespace
}  // namespace canfleet::control
