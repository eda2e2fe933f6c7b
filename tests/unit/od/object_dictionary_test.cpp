// Object dictionary access rules, CiA 301 v4.2 §7.4 (OD structure) and §7.2.4.3.17 (abort codes).
#include "node/canopen/od/object_dictionary.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace canfleet::canopen {
namespace {

class ObjectDictionaryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    od.AddVar(0x1000, "Device type", DataType::kUnsigned32, Access::kRo, EncodeLe<std::uint32_t>(0x000F0194));
    od.AddVar(0x1017, "Producer heartbeat time", DataType::kUnsigned16, Access::kRw,
              EncodeLe<std::uint16_t>(0));
    od.AddVar(0x6125, "Autozero", DataType::kUnsigned32, Access::kWo, EncodeLe<std::uint32_t>(0));
    od.AddVar(0x5555, "Start in operational", DataType::kBoolean, Access::kRw, {0});
    auto& limited =
        od.AddVar(0x2090, "Window", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(1000));
    limited.low_limit = EncodeLe<std::uint16_t>(10);
    limited.high_limit = EncodeLe<std::uint16_t>(10000);
    auto& signed_limited =
        od.AddVar(0x3030, "Min current", DataType::kInteger16, Access::kRw, EncodeLe<std::int16_t>(0));
    signed_limited.low_limit = EncodeLe<std::int16_t>(-100);
    signed_limited.high_limit = EncodeLe<std::int16_t>(2000);
    od.AddVar(0x1008, "Name", DataType::kVisibleString, Access::kConst, ToBytes("AX020506"));
  }
  ObjectDictionary od;
};

TEST_F(ObjectDictionaryTest, MissingObjectAndSubIndexGiveTheirAbortCodes) {
  Bytes out;
  EXPECT_EQ(od.Read(0x1234, 0, out), SdoAbort::kNoObject);
  EXPECT_EQ(od.Read(0x1000, 1, out), SdoAbort::kNoSubIndex);
  EXPECT_EQ(od.Write(0x1234, 0, out), SdoAbort::kNoObject);
}

TEST_F(ObjectDictionaryTest, AccessTypesAreEnforcedForSdoButNotForTheDevice) {
  Bytes out;
  EXPECT_EQ(od.Write(0x1000, 0, EncodeLe<std::uint32_t>(1)), SdoAbort::kReadOnly);
  EXPECT_EQ(od.Write(0x1008, 0, ToBytes("x")), SdoAbort::kReadOnly);  // const
  EXPECT_EQ(od.Read(0x6125, 0, out), SdoAbort::kWriteOnly);
  EXPECT_EQ(od.Write(0x1000, 0, EncodeLe<std::uint32_t>(1), Origin::kDevice), SdoAbort::kNone);
  EXPECT_EQ(od.GetUnsigned(0x1000, 0), 1u);
}

TEST_F(ObjectDictionaryTest, LengthMustMatchFixedSizeTypes) {
  EXPECT_EQ(od.Write(0x1017, 0, Bytes{1, 2, 3}), SdoAbort::kLengthTooHigh);
  EXPECT_EQ(od.Write(0x1017, 0, Bytes{1}), SdoAbort::kLengthTooLow);
  EXPECT_EQ(od.Write(0x1017, 0, Bytes{0xE8, 0x03}), SdoAbort::kNone);
  EXPECT_EQ(od.GetUnsigned(0x1017, 0), 1000u);
}

TEST_F(ObjectDictionaryTest, LimitsGiveValueTooHighOrTooLow) {
  EXPECT_EQ(od.Write(0x2090, 0, EncodeLe<std::uint16_t>(9)), SdoAbort::kValueTooLow);
  EXPECT_EQ(od.Write(0x2090, 0, EncodeLe<std::uint16_t>(10001)), SdoAbort::kValueTooHigh);
  EXPECT_EQ(od.Write(0x2090, 0, EncodeLe<std::uint16_t>(10000)), SdoAbort::kNone);
  EXPECT_EQ(od.Write(0x3030, 0, EncodeLe<std::int16_t>(-101)), SdoAbort::kValueTooLow);
  EXPECT_EQ(od.Write(0x3030, 0, EncodeLe<std::int16_t>(-100)), SdoAbort::kNone);
  EXPECT_EQ(od.GetSigned(0x3030, 0), -100);
}

TEST_F(ObjectDictionaryTest, BooleanAcceptsOnlyZeroAndOne) {
  EXPECT_EQ(od.Write(0x5555, 0, Bytes{2}), SdoAbort::kInvalidValue);
  EXPECT_EQ(od.Write(0x5555, 0, Bytes{1}), SdoAbort::kNone);
}

TEST_F(ObjectDictionaryTest, ValidatorsVetoAndListenersReact) {
  auto* sub = od.Find(0x1017, 0);
  int notified = 0;
  sub->AddValidator([](const SubObject&, std::span<const std::uint8_t> data, Origin) {
    return DecodeUnsignedLe(data) == 7 ? SdoAbort::kInvalidValue : SdoAbort::kNone;
  });
  sub->AddListener([&](SubObject&, Origin) { ++notified; });
  EXPECT_EQ(od.Write(0x1017, 0, EncodeLe<std::uint16_t>(7)), SdoAbort::kInvalidValue);
  EXPECT_EQ(notified, 0);
  EXPECT_EQ(od.GetUnsigned(0x1017, 0), 0u);  // a vetoed write leaves the old value
  EXPECT_EQ(od.Write(0x1017, 0, EncodeLe<std::uint16_t>(8)), SdoAbort::kNone);
  EXPECT_EQ(notified, 1);
}

TEST_F(ObjectDictionaryTest, ReadHooksComputeOrRefuse) {
  auto* sub = od.Find(0x1017, 0);
  sub->AddReadHook([](SubObject& s, Origin) {
    s.value = EncodeLe<std::uint16_t>(123);
    return SdoAbort::kNone;
  });
  Bytes out;
  ASSERT_EQ(od.Read(0x1017, 0, out), SdoAbort::kNone);
  EXPECT_EQ(DecodeUnsignedLe(out), 123u);
  sub->AddReadHook([](SubObject&, Origin) { return SdoAbort::kNoData; });
  EXPECT_EQ(od.Read(0x1017, 0, out), SdoAbort::kNoData);
}

TEST_F(ObjectDictionaryTest, NodeIdRelativeDefaultsAreAppliedOnRestore) {
  Object tpdo;
  tpdo.index = 0x1800;
  tpdo.code = ObjectCode::kRecord;
  SubObject count;
  count.type = DataType::kUnsigned8;
  count.access = Access::kConst;
  count.default_value = {1};
  SubObject cob;
  cob.type = DataType::kUnsigned32;
  cob.default_value = EncodeLe<std::uint32_t>(0x40000180);
  cob.default_adds_node_id = true;
  tpdo.subs.emplace(0, count);
  tpdo.subs.emplace(1, cob);
  od.Add(tpdo);
  od.RestoreDefaults(0x1000, 0x1FFF, 5);
  EXPECT_EQ(od.GetUnsigned(0x1800, 1), 0x40000185u);
  od.RestoreDefaults(0x1000, 0x1FFF, 0x7F);
  EXPECT_EQ(od.GetUnsigned(0x1800, 1), 0x400001FFu);
}

TEST_F(ObjectDictionaryTest, RestoreDefaultsOnlyTouchesTheRange) {
  od.Write(0x2090, 0, EncodeLe<std::uint16_t>(50));
  od.Write(0x1017, 0, EncodeLe<std::uint16_t>(50));
  od.RestoreDefaults(0x1000, 0x1FFF, 1);
  EXPECT_EQ(od.GetUnsigned(0x1017, 0), 0u);
  EXPECT_EQ(od.GetUnsigned(0x2090, 0), 50u);
}

TEST(Value, SignExtensionAndFormatting) {
  EXPECT_EQ(DecodeSignedLe(Bytes{0xFF, 0xFF}), -1);
  EXPECT_EQ(DecodeSignedLe(Bytes{0xFF, 0x7F}), 32767);
  EXPECT_EQ(FormatValue(DataType::kInteger16, EncodeLe<std::int16_t>(-5)), "-5");
  EXPECT_EQ(FormatValue(DataType::kReal32, EncodeLe<float>(1.5f)), "1.5");
  EXPECT_EQ(FormatValue(DataType::kVisibleString, ToBytes("ab")), "\"ab\"");
  EXPECT_EQ(FormatValue(DataType::kDomain, Bytes{0xDE, 0xAD}), "DEAD");
}

// Dictionary-wide write listeners: one for "any write" instead of one per sub-object (idle RSS).
TEST(DictionaryWriteListenerTest, RunsAfterTheSubObjectsOwnListenersAndOnRestore) {
  ObjectDictionary od;
  auto& sub = od.AddVar(0x2000, "Value", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(7));
  std::vector<std::string> calls;
  sub.AddListener([&](SubObject&, Origin) { calls.push_back("sub"); });
  od.AddWriteListener([&](SubObject& s, Origin origin) {
    calls.push_back("od " + std::to_string(s.index) + (origin == Origin::kDevice ? " device" : " sdo"));
  });
  EXPECT_EQ(od.Write(0x2000, 0, EncodeLe<std::uint16_t>(9)), SdoAbort::kNone);
  od.RestoreDefaults(0x1000, 0xFFFF, 1);
  EXPECT_EQ(calls, (std::vector<std::string>{"sub", "od 8192 sdo", "sub", "od 8192 device"}));
}

TEST(DictionaryWriteListenerTest, SeesWritesToBorrowedObjects) {
  ObjectDictionary owner, borrower;
  owner.AddVar(0x2000, "Shared", DataType::kUnsigned8, Access::kRw, {0});
  borrower.Borrow(*owner.Find(0x2000));
  int heard = 0;
  borrower.AddWriteListener([&](SubObject&, Origin) { ++heard; });
  EXPECT_EQ(borrower.Write(0x2000, 0, std::vector<std::uint8_t>{5}), SdoAbort::kNone);
  EXPECT_EQ(heard, 1);
}

TEST(SubObjectHooksTest, SubObjectWithoutHooksHasEmptyListsAndCopiesKeepHooks) {
  ObjectDictionary od;
  auto& sub = od.AddVar(0x2000, "Value", DataType::kUnsigned8, Access::kRw, {0});
  EXPECT_TRUE(sub.read_hooks().empty());
  EXPECT_TRUE(sub.validators().empty());
  EXPECT_TRUE(sub.listeners().empty());
  sub.AddValidator([](const SubObject&, std::span<const std::uint8_t> data, Origin) {
    return data[0] > 3 ? SdoAbort::kValueTooHigh : SdoAbort::kNone;
  });
  ObjectDictionary copy = od;
  EXPECT_EQ(copy.Write(0x2000, 0, std::vector<std::uint8_t>{4}), SdoAbort::kValueTooHigh);
  EXPECT_EQ(copy.Write(0x2000, 0, std::vector<std::uint8_t>{2}), SdoAbort::kNone);
  EXPECT_EQ(od.GetUnsigned(0x2000, 0), 0u);  // the copy's value is its own
}

}  // namespace
}  // namespace canfleet::canopen
