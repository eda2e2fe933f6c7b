// Analog input software filters (61A0h/61A1h): valve UMAX020411A §1.3 Table 8, logger UMAX181001
// §1.4 Table 9, encoder AX023241 §1.2.3 Table 5. Step responses through the AnalogInput chain,
// 1.000 V (3 digits) = 1000 mV field value.
#include <gtest/gtest.h>

#include <chrono>

#include "node/devices/blocks/analog_input.hpp"

namespace canfleet::devices::blocks::test {
namespace {

using namespace std::chrono_literals;

AnalogInputParams Filtered(FilterType type, std::uint16_t constant) {
  AnalogInputParams p;
  p.filter.type = type;
  p.filter.constant = constant;
  p.span.enabled = false;
  return p;
}

// Table 8 value 0: "Value = Input", a snapshot.
TEST(InputFilterTest, NoFilterTakesTheInput) {
  AnalogInput ai;
  const AnalogInputParams p = Filtered(FilterType::kNone, 10);
  ai.Tick(1ms, p, 2.5);
  EXPECT_EQ(ai.FieldValue(), 2500);
  EXPECT_FALSE(ai.Busy());
}

// §1.3 moving average, "called every 1ms": V[n] = V[n-1] + (In - V[n-1]) / 10:
// 100, 190, 271, ..., 1000 x (1 - 0.9^10) = 651 after 10 ms.
TEST(InputFilterTest, MovingAverageStepResponse) {
  AnalogInput ai;
  const AnalogInputParams p = Filtered(FilterType::kMovingAverage, 10);
  ai.Tick(1ms, p, 1.0);
  EXPECT_EQ(ai.FieldValue(), 100);
  ai.Tick(1ms, p, 1.0);
  EXPECT_EQ(ai.FieldValue(), 190);
  ai.Tick(1ms, p, 1.0);
  EXPECT_EQ(ai.FieldValue(), 271);
  ai.Tick(7ms, p, 1.0);
  EXPECT_EQ(ai.FieldValue(), 651);
  EXPECT_TRUE(ai.Busy());
  ai.Tick(1000ms, p, 1.0);
  EXPECT_EQ(ai.FieldValue(), 1000);
  EXPECT_DOUBLE_EQ(ai.filter().Value(), 1000.0);
  EXPECT_FALSE(ai.Busy());
}

// §1.3 repeating average: "At every Nth read, the sum is divided by N, and the result is the new
// input value. The value and counter will be set to zero for the next read." Held in between.
TEST(InputFilterTest, RepeatingAverageHoldsBetweenAverages) {
  AnalogInput ai;
  const AnalogInputParams p = Filtered(FilterType::kRepeatingAverage, 10);
  ai.Tick(5ms, p, 1.0);
  ai.Tick(4ms, p, 2.0);
  EXPECT_EQ(ai.FieldValue(), 0);
  EXPECT_TRUE(ai.Busy());
  ai.Tick(1ms, p, 2.0);
  EXPECT_EQ(ai.FieldValue(), 1500);
  ai.Tick(9ms, p, 2.0);
  EXPECT_EQ(ai.FieldValue(), 1500);
  ai.Tick(1ms, p, 2.0);
  EXPECT_EQ(ai.FieldValue(), 2000);
  EXPECT_FALSE(ai.Busy());
}

// §1.3 third-order low pass with the defaults (2120h-2127h: P 10, N 120/241/120/0, O 704/-164/0),
// run every 61A1h = 10 ms, holding in between:
//   10 ms: 120*1000 >> 10 = 117
//   20 ms: (120*1000 + 241*1000 + 704*117) >> 10 = 432
//   30 ms: (120*1000 + 241*1000 + 120*1000 + 704*432 - 164*117) >> 10 = 747
// and it settles a little below the input (DC gain 481/484).
TEST(InputFilterTest, ThirdOrderLowPassStepResponse) {
  AnalogInput ai;
  const AnalogInputParams p = Filtered(FilterType::kThirdOrderLowPass, 10);
  ai.Tick(9ms, p, 1.0);
  EXPECT_EQ(ai.FieldValue(), 0);
  ai.Tick(1ms, p, 1.0);
  EXPECT_EQ(ai.FieldValue(), 117);
  ai.Tick(5ms, p, 1.0);
  EXPECT_EQ(ai.FieldValue(), 117);
  ai.Tick(5ms, p, 1.0);
  EXPECT_EQ(ai.FieldValue(), 432);
  ai.Tick(10ms, p, 1.0);
  EXPECT_EQ(ai.FieldValue(), 747);
  ai.Tick(1000ms, p, 1.0);
  EXPECT_GE(ai.FieldValue(), 990);
  EXPECT_LE(ai.FieldValue(), 994);
  EXPECT_FALSE(ai.Busy());
}

// ">> P" on a negative sum is an arithmetic shift (floor): -1000 mV settles a little above -1000.
TEST(InputFilterTest, ThirdOrderLowPassHandlesNegativeInputs) {
  AnalogInput ai;
  const AnalogInputParams p = Filtered(FilterType::kThirdOrderLowPass, 1);
  ai.Tick(1ms, p, -1.0);
  EXPECT_EQ(ai.FieldValue(), -118);  // floor(-117.19)
  ai.Tick(1000ms, p, -1.0);
  EXPECT_LE(ai.FieldValue(), -990);
  EXPECT_FALSE(ai.Busy());
}

// Valve Table 8 / logger Table 9 have the third-order filter; encoder Table 5 stops at 2.
TEST(InputFilterTest, FilterTypesDifferPerProduct) {
  EXPECT_EQ(DecodeFilterType(3, true), FilterType::kThirdOrderLowPass);
  EXPECT_EQ(DecodeFilterType(4, true), std::nullopt);
  EXPECT_EQ(DecodeFilterType(2, false), FilterType::kRepeatingAverage);
  EXPECT_EQ(DecodeFilterType(3, false), std::nullopt);
}

}  // namespace
}  // namespace canfleet::devices::blocks::test
