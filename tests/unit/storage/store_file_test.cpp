// The store file format (store_file.hpp): encoding round trips, and every way a file can be
// damaged is recognised without reading outside the buffer.
#include "node/canopen/storage/store_file.hpp"

#include <gtest/gtest.h>

#include <string_view>

namespace canfleet::canopen {
namespace {

StoreImage SampleImage() {
  StoreImage image;
  image.group = StoreGroup::kCommunication;
  image.vendor_id = 0x55;
  image.product_code = 0xAA020411;
  image.entries.push_back({0x1017, 0, DataType::kUnsigned16, false, EncodeLe<std::uint16_t>(500)});
  image.entries.push_back({0x1800, 1, DataType::kUnsigned32, true, EncodeLe<std::uint32_t>(0x40000180)});
  image.entries.push_back({0x1008, 0, DataType::kVisibleString, false, ToBytes("canfleet")});
  image.entries.push_back({0x1009, 0, DataType::kVisibleString, false, {}});
  return image;
}

/// Recomputes length and CRC so that a test reaches the checks behind them.
void Reseal(Bytes& file) {
  const std::uint32_t length = static_cast<std::uint32_t>(file.size() - kStoreHeaderSize);
  const std::uint32_t crc = Crc32(std::span<const std::uint8_t>(file).subspan(kStoreHeaderSize));
  for (int i = 0; i < 4; ++i) {
    file[8 + i] = static_cast<std::uint8_t>(length >> (8 * i));
    file[12 + i] = static_cast<std::uint8_t>(crc >> (8 * i));
  }
}

TEST(StoreFile, Crc32IsTheIeeeCrc) {
  const std::string_view check = "123456789";
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(check.data());
  EXPECT_EQ(Crc32({bytes, check.size()}), 0xCBF43926u);
  // Continuation gives the same result as one call.
  EXPECT_EQ(Crc32({bytes + 4, 5}, Crc32({bytes, 4})), 0xCBF43926u);
  EXPECT_EQ(Crc32({}), 0u);
}

TEST(StoreFile, RoundTripsEntries) {
  const auto image = SampleImage();
  const Bytes file = EncodeStoreFile(image);
  ASSERT_GE(file.size(), kStoreHeaderSize);
  EXPECT_EQ(std::string(file.begin(), file.begin() + 4), "CFPS");
  const auto decoded = DecodeStoreFile(file, StoreGroup::kCommunication);
  ASSERT_TRUE(decoded.image) << decoded.detail;
  EXPECT_EQ(decoded.image->vendor_id, 0x55u);
  EXPECT_EQ(decoded.image->product_code, 0xAA020411u);
  EXPECT_EQ(decoded.image->entries, image.entries);
}

TEST(StoreFile, RoundTripsLssConfiguration) {
  StoreImage image;
  image.group = StoreGroup::kLss;
  image.lss = {0x20, 3};
  const auto decoded = DecodeStoreFile(EncodeStoreFile(image), StoreGroup::kLss);
  ASSERT_TRUE(decoded.image) << decoded.detail;
  EXPECT_EQ(decoded.image->lss, (LssConfig{0x20, 3}));
}

TEST(StoreFile, EmptyMagicVersionAndHeaderProblemsAreNamed) {
  const Bytes good = EncodeStoreFile(SampleImage());
  EXPECT_EQ(DecodeStoreFile({}, StoreGroup::kCommunication).problem, StoreProblem::kEmpty);
  Bytes bad = good;
  bad[0] = 'X';
  EXPECT_EQ(DecodeStoreFile(bad, StoreGroup::kCommunication).problem, StoreProblem::kBadMagic);
  bad = good;
  bad[4] = 2;  // version 2
  EXPECT_EQ(DecodeStoreFile(bad, StoreGroup::kCommunication).problem, StoreProblem::kBadVersion);
  bad = good;
  bad[7] = 1;
  EXPECT_EQ(DecodeStoreFile(bad, StoreGroup::kCommunication).problem, StoreProblem::kBadHeader);
  bad = good;
  bad.push_back(0);
  EXPECT_EQ(DecodeStoreFile(bad, StoreGroup::kCommunication).problem, StoreProblem::kBadLength);
  EXPECT_EQ(DecodeStoreFile(good, StoreGroup::kApplication).problem, StoreProblem::kForeign);
}

TEST(StoreFile, EveryTruncationIsRecognised) {
  const Bytes good = EncodeStoreFile(SampleImage());
  for (std::size_t n = 0; n < good.size(); ++n) {
    const auto decoded =
        DecodeStoreFile(std::span<const std::uint8_t>(good).first(n), StoreGroup::kCommunication);
    EXPECT_FALSE(decoded.image) << n;
    const auto expected = n == 0 ? StoreProblem::kEmpty : StoreProblem::kTruncated;
    EXPECT_EQ(decoded.problem, expected) << n << " bytes: " << decoded.detail;
  }
}

TEST(StoreFile, EverySingleBitFlipIsRecognised) {
  const Bytes good = EncodeStoreFile(SampleImage());
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      Bytes bad = good;
      bad[i] ^= static_cast<std::uint8_t>(1 << bit);
      EXPECT_FALSE(DecodeStoreFile(bad, StoreGroup::kCommunication).image) << "byte " << i << " bit " << bit;
    }
  }
}

// With a valid CRC the payload itself must still parse: counts and lengths can lie.
TEST(StoreFile, MalformedPayloadBehindAValidCrcIsRefused) {
  Bytes file = EncodeStoreFile(SampleImage());
  // Entry count 1000 with four entries present.
  Bytes lying_count = file;
  lying_count[kStoreHeaderSize + 8] = 0xE8;
  lying_count[kStoreHeaderSize + 9] = 0x03;
  Reseal(lying_count);
  EXPECT_EQ(DecodeStoreFile(lying_count, StoreGroup::kCommunication).problem, StoreProblem::kMalformed);
  // Entry count 0xFFFFFFFF must not reserve memory for it.
  Bytes huge_count = file;
  for (int i = 0; i < 4; ++i)
    huge_count[kStoreHeaderSize + 8 + i] = 0xFF;
  Reseal(huge_count);
  EXPECT_EQ(DecodeStoreFile(huge_count, StoreGroup::kCommunication).problem, StoreProblem::kMalformed);
  // First entry's value length 0xFFFF.
  Bytes long_value = file;
  long_value[kStoreHeaderSize + 12 + 6] = 0xFF;
  long_value[kStoreHeaderSize + 12 + 7] = 0xFF;
  Reseal(long_value);
  EXPECT_EQ(DecodeStoreFile(long_value, StoreGroup::kCommunication).problem, StoreProblem::kMalformed);
  // Unknown flag bits.
  Bytes flags = file;
  flags[kStoreHeaderSize + 12 + 5] = 0x80;
  Reseal(flags);
  EXPECT_EQ(DecodeStoreFile(flags, StoreGroup::kCommunication).problem, StoreProblem::kMalformed);
  // Trailing bytes after the last entry.
  Bytes trailing = file;
  trailing.push_back(0);
  Reseal(trailing);
  EXPECT_EQ(DecodeStoreFile(trailing, StoreGroup::kCommunication).problem, StoreProblem::kMalformed);
  // Payload too short for the identity.
  Bytes tiny(file.begin(), file.begin() + kStoreHeaderSize + 3);
  Reseal(tiny);
  EXPECT_EQ(DecodeStoreFile(tiny, StoreGroup::kCommunication).problem, StoreProblem::kMalformed);
}

}  // namespace
}  // namespace canfleet::canopen
