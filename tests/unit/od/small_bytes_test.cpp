// SmallBytes: OD values kept inline up to 8 bytes (idle RSS, bench/idle/README.md).
#include "node/canopen/od/small_bytes.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace canfleet::canopen {
namespace {

using Vec = std::vector<std::uint8_t>;

TEST(SmallBytesTest, HoldsNumbersInlineAndLongerValuesOnTheHeap) {
  SmallBytes number = Vec{1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_EQ(number.size(), 8u);
  EXPECT_GE(number.data(), reinterpret_cast<const std::uint8_t*>(&number));
  EXPECT_LT(number.data(), reinterpret_cast<const std::uint8_t*>(&number + 1));  // inside the object
  const std::string text = "a visible string longer than eight bytes";
  SmallBytes string(Vec(text.begin(), text.end()));
  EXPECT_EQ(std::string(string.begin(), string.end()), text);
}

TEST(SmallBytesTest, AssignKeepsTheBufferAndCopiesAreDeep) {
  SmallBytes value = Vec(12, 0xAA);
  const std::uint8_t* buffer = value.data();
  const Vec shorter{1, 2, 3};
  value.assign(shorter.begin(), shorter.end());
  EXPECT_EQ(value.data(), buffer);  // no allocation when the size does not grow (RPDO path)
  EXPECT_EQ(value, shorter);
  SmallBytes copy = value;
  copy[0] = 9;
  EXPECT_EQ(value, (Vec{1, 2, 3}));
  SmallBytes moved = std::move(copy);
  EXPECT_EQ(moved, (Vec{9, 2, 3}));
  value = moved;
  EXPECT_EQ(value, moved);
}

TEST(SmallBytesTest, ConvertsToVectorAndSpanAndResizes) {
  SmallBytes value{1, 2};
  const Vec as_vector = value;
  EXPECT_EQ(as_vector, (Vec{1, 2}));
  const std::span<const std::uint8_t> view = value;
  EXPECT_EQ(view.size(), 2u);
  value.resize(10);
  EXPECT_EQ(value, (Vec{1, 2, 0, 0, 0, 0, 0, 0, 0, 0}));
  value.clear();
  EXPECT_TRUE(value.empty());
}

}  // namespace
}  // namespace canfleet::canopen
