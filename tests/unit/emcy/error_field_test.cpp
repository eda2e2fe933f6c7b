// The pre-defined error field 1003h (CiA 301 v4.2 §7.5.2.4) as the five device manuals use it:
// newest entry at sub-index 1, sub-index 0 = count, an entry leaves when its error clears, writing
// 0 to sub-index 0 empties the list but not the error state. And the objects AddEmcyObjects makes.
#include "tests/unit/emcy/emcy_fixture.hpp"

namespace canfleet::canopen {
namespace {

// §7.5.2.4: the newest error at sub-index 1, older ones move down; beyond the declared size the
// oldest falls off. Clearing an error that already fell off leaves the list alone.
TEST_F(EmcyTest, HistoryIsNewestFirstAndCappedAtTheDeclaredSize) {
  auto& emcy = Start({}, 4);
  for (std::uint16_t channel = 1; channel <= 5; ++channel)
    emcy.Raise(Error(0xF001, 0x2000 | channel));
  EXPECT_EQ(ErrorField(), (std::vector<std::uint32_t>{0x2005F001, 0x2004F001, 0x2003F001, 0x2002F001}));
  EXPECT_EQ(emcy.ActiveCount(), 5u);
  emcy.Clear(0xF001, 0x2001);
  EXPECT_EQ(ErrorField(), (std::vector<std::uint32_t>{0x2005F001, 0x2004F001, 0x2003F001, 0x2002F001}));
}

// Power supply: 15 sub-indexes declared, at most 4 kept; reading sub-index 5 then has no data.
TEST_F(EmcyTest, MaxHistoryKeepsFewerEntriesThanDeclared) {
  auto& emcy = Start({.max_history = 4}, 15);
  for (std::uint16_t i = 1; i <= 6; ++i)
    emcy.Raise(Error(0xFF04, i));
  EXPECT_EQ(Get(0x1003, 0), 4u);
  EXPECT_EQ(ErrorField(), (std::vector<std::uint32_t>{0x0006FF04, 0x0005FF04, 0x0004FF04, 0x0003FF04}));
  Bytes out;
  EXPECT_EQ(od.Read(0x1003, 5, out), SdoAbort::kNoData);
}

// With removal off, cleared errors stay in the history until newer ones push them out.
TEST_F(EmcyTest, ClearedEntriesStayWhenRemovalIsOff) {
  auto& emcy = Start({.remove_cleared_from_history = false});
  emcy.Raise(Error(0x2320, 0x0401));
  emcy.Clear(0x2320, 0x0401);
  EXPECT_EQ(ErrorField(), std::vector<std::uint32_t>{0x04012320});
  EXPECT_EQ(Get(0x1001), 0u);
}

// §7.5.2.4: writing 0 to sub-index 0 deletes the history. The manuals: "write 0 to clear the list,
// still-active errors stay active" – 1001h unchanged, no frame; a later clear still resets.
TEST_F(EmcyTest, WritingZeroToTheCountEmptiesTheListButKeepsActiveErrors) {
  auto& emcy = Start();
  emcy.Raise(Error(0x2320, 0x0401, kErrorRegisterCurrent));
  emcy.Raise(Error(0x3300, 0x0102, kErrorRegisterVoltage));
  probe.Clear();
  EXPECT_EQ(od.Write(0x1003, 0, Bytes{0}), SdoAbort::kNone);
  EXPECT_TRUE(ErrorField().empty());
  EXPECT_EQ(Get(0x1003, 1), 0u);
  EXPECT_EQ(Get(0x1001), 0x07u);
  EXPECT_EQ(emcy.ActiveCount(), 2u);
  EXPECT_EQ(probe.Count(), 0u);
  emcy.Clear(0x3300, 0x0102);
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"085#0000030000000000"});
  emcy.Raise(Error(0x4210, 0x0001, kErrorRegisterTemperature));
  EXPECT_EQ(ErrorField(), std::vector<std::uint32_t>{0x00014210});
}

// §7.5.2.4 / CANopenNode OD_write_1003: any other value is refused with 06090030h.
TEST_F(EmcyTest, WritingANonZeroCountIsRefused) {
  auto& emcy = Start();
  emcy.Raise(Error(0x2320, 0x0401));
  EXPECT_EQ(od.Write(0x1003, 0, Bytes{1}), SdoAbort::kInvalidValue);
  EXPECT_EQ(od.Write(0x1003, 0, Bytes{5}), SdoAbort::kInvalidValue);
  EXPECT_EQ(ErrorField(), std::vector<std::uint32_t>{0x04012320});
}

// CANopenNode OD_read_1003: a sub-index past the count answers 08000024h (no data); past the
// declared size the OD answers 06090011h. The entries are read-only.
TEST_F(EmcyTest, ReadingPastTheCountAnswersNoData) {
  auto& emcy = Start({}, 4);
  emcy.Raise(Error(0x2320, 0x0401));
  Bytes out;
  EXPECT_EQ(od.Read(0x1003, 1, out), SdoAbort::kNone);
  EXPECT_EQ(DecodeUnsignedLe(out), 0x04012320u);
  EXPECT_EQ(od.Read(0x1003, 2, out), SdoAbort::kNoData);
  EXPECT_EQ(od.Read(0x1003, 4, out), SdoAbort::kNoData);
  EXPECT_EQ(od.Read(0x1003, 5, out), SdoAbort::kNoSubIndex);
  EXPECT_EQ(od.Write(0x1003, 1, EncodeLe<std::uint32_t>(0)), SdoAbort::kReadOnly);
}

// Entries declared rw by a device file are still read-only to the network.
TEST_F(EmcyTest, EntriesDeclaredWritableAreStillReadOnly) {
  AddEmcyObjects(od, 2);
  od.Find(0x1003, 1)->access = Access::kRw;
  auto& emcy = StartOn();
  emcy.Raise(Error(0x2320, 0x0401));
  EXPECT_EQ(od.Write(0x1003, 1, EncodeLe<std::uint32_t>(0x12345678)), SdoAbort::kReadOnly);
  EXPECT_EQ(ErrorField(), std::vector<std::uint32_t>{0x04012320});
}

// Reset communication restores 1000h-1FFFh defaults; the service puts its state back, so the
// error state and history survive it (reset node goes through ClearAll()).
TEST_F(EmcyTest, RestoringDefaultsKeepsTheErrorState) {
  auto& emcy = Start();
  emcy.Raise(Error(0x2320, 0x0401, kErrorRegisterCurrent));
  od.RestoreDefaults(0x1000, 0x1FFF, 5);
  EXPECT_EQ(Get(0x1001), 0x03u);
  EXPECT_EQ(ErrorField(), std::vector<std::uint32_t>{0x04012320});
  EXPECT_EQ(Get(0x1014), 0x85u);
}

// An EDS default for the count (the encoder prints 15) does not invent entries.
TEST_F(EmcyTest, ANonZeroDefaultCountIsCorrected) {
  AddEmcyObjects(od, 15);
  od.Find(0x1003, 0)->default_value = {15};
  StartOn();
  EXPECT_EQ(Get(0x1003, 0), 0u);
  EXPECT_TRUE(ErrorField().empty());
}

TEST(EmcyObjects, AddEmcyObjectsCreatesTheCiA301Objects) {
  ObjectDictionary od;
  AddEmcyObjects(od, 3);
  const SubObject* reg = od.Find(0x1001, 0);
  ASSERT_NE(reg, nullptr);
  EXPECT_EQ(reg->type, DataType::kUnsigned8);
  EXPECT_EQ(reg->access, Access::kRo);
  EXPECT_EQ(reg->value, Bytes{0});

  const Object* field = od.Find(0x1003);
  ASSERT_NE(field, nullptr);
  EXPECT_EQ(field->code, ObjectCode::kArray);
  ASSERT_EQ(field->subs.size(), 4u);
  EXPECT_EQ(field->subs.at(0).type, DataType::kUnsigned8);
  EXPECT_EQ(field->subs.at(0).access, Access::kRw);
  for (std::uint8_t sub = 1; sub <= 3; ++sub) {
    EXPECT_EQ(field->subs.at(sub).type, DataType::kUnsigned32);
    EXPECT_EQ(field->subs.at(sub).access, Access::kRo);
  }

  const SubObject* cob_id = od.Find(0x1014, 0);
  ASSERT_NE(cob_id, nullptr);
  EXPECT_EQ(cob_id->type, DataType::kUnsigned32);
  EXPECT_EQ(cob_id->access, Access::kRw);
  EXPECT_EQ(DecodeUnsignedLe(cob_id->DefaultFor(5)), 0x85u);  // $NODEID+0x80

  const SubObject* inhibit = od.Find(0x1015, 0);
  ASSERT_NE(inhibit, nullptr);
  EXPECT_EQ(inhibit->type, DataType::kUnsigned16);
  EXPECT_EQ(inhibit->access, Access::kRw);
  EXPECT_EQ(DecodeUnsignedLe(inhibit->value), 0u);
}

TEST(EmcyObjects, NoHistoryEntriesMeansNo1003h) {
  ObjectDictionary od;
  AddEmcyObjects(od, 0);
  EXPECT_EQ(od.Find(0x1003), nullptr);
  EXPECT_NE(od.Find(0x1001), nullptr);
}

}  // namespace
}  // namespace canfleet::canopen
