// PDO objects: CiA 301 v4.2 §7.5.2.35–38 (1400h/1600h/1800h/1A00h) and the pre-defined connection
// set (facts §1); which records make a PDO.
#include "tests/unit/pdo/pdo_fixture.hpp"

namespace canfleet::canopen::test_pdo {
namespace {

// Pre-defined connection set: PDOs 1–4 on 180h/200h... + node-ID, valid, no RTR; later PDOs not
// valid. Type 255, nothing mapped, 8 mapping entries; RPDO comm sub0 = 5, TPDO comm sub0 = 6.
TEST_F(PdoTest, AddPdoObjectsGivesThePredefinedConnectionSet) {
  EXPECT_EQ(od.GetUnsigned(0x1400, 1), 0x40000205u);
  EXPECT_EQ(od.GetUnsigned(0x1401, 1), 0x40000305u);
  EXPECT_EQ(od.GetUnsigned(0x1402, 1), 0x40000405u);
  EXPECT_EQ(od.GetUnsigned(0x1403, 1), 0x40000505u);
  EXPECT_EQ(od.GetUnsigned(0x1800, 1), 0x40000185u);
  EXPECT_EQ(od.GetUnsigned(0x1801, 1), 0x40000285u);
  EXPECT_EQ(od.GetUnsigned(0x1802, 1), 0x40000385u);
  EXPECT_EQ(od.GetUnsigned(0x1803, 1), 0x40000485u);
  EXPECT_EQ(od.GetUnsigned(0x1400, 0), 5u);
  EXPECT_EQ(od.GetUnsigned(0x1800, 0), 6u);
  EXPECT_EQ(od.Find(0x1400, 6), nullptr);
  EXPECT_EQ(od.GetUnsigned(0x1800, 2), 255u);
  EXPECT_EQ(od.GetUnsigned(0x1400, 2), 255u);
  EXPECT_EQ(od.GetUnsigned(0x1A03, 0), 0u);
  EXPECT_NE(od.Find(0x1A03, 8), nullptr);
  EXPECT_EQ(od.Find(0x1A03, 9), nullptr);
  EXPECT_EQ(od.Find(0x1404), nullptr);

  ObjectDictionary more;
  AddPdoObjects(more, 6, 10);
  more.RestoreDefaults(0x1000, 0x1FFF, kNodeId);
  EXPECT_EQ(more.GetUnsigned(0x1405, 1), 0x80000000u);
  EXPECT_EQ(more.GetUnsigned(0x1809, 1), 0x80000000u);
  EXPECT_NE(more.Find(0x1A09), nullptr);
}

// The service finds as many PDOs as the dictionary declares (1400h–15FFh, 1800h–19FFh), numbered
// by index, and tolerates gaps and a missing mapping record.
TEST_F(PdoTest, ServiceScansTheDeclaredPdos) {
  Object tpdo10;
  tpdo10.index = 0x1809;  // TPDO10 without a mapping record, and no TPDO5..9
  tpdo10.code = ObjectCode::kRecord;
  SubObject cob;
  cob.type = DataType::kUnsigned32;
  cob.default_value = EncodeLe<std::uint32_t>(0x40000182 + kNodeId);  // like the 12-in/12-out valve TPDO10
  tpdo10.subs.emplace(1, cob);
  od.Add(tpdo10);
  Start();
  EXPECT_EQ(pdo->RpdoCount(), 4u);
  EXPECT_EQ(pdo->TpdoCount(), 5u);
  Operational();
  pdo->RequestTpdo(10);  // valid but maps nothing: sends nothing
  pdo->RequestTpdo(7);   // no such TPDO
  pdo->RequestTpdo(0);
  pdo->RequestTpdo(600);
  EXPECT_EQ(master.Count(), 0u);
}

// Reset communication restores 1400h–1FFFh with the new node-ID; SetNodeId re-reads them, so a
// mapped TPDO moves to the new COB-ID.
TEST_F(PdoTest, RestoredDefaultsAndSetNodeIdMoveThePdos) {
  auto* count = od.Find(0x1A00, 0);
  auto* entry = od.Find(0x1A00, 1);
  count->default_value = {1};
  entry->default_value = EncodeLe<std::uint32_t>(0x60000108);
  od.RestoreDefaults(0x1000, 0x1FFF, kNodeId);
  Start();
  Operational();
  Set(0x6000, 1, 0x5A);
  pdo->RequestTpdo(1);
  od.RestoreDefaults(0x1000, 0x1FFF, 6);
  pdo->SetNodeId(6);
  pdo->RequestTpdo(1);
  EXPECT_EQ(master.Take(), (Frames{"185#5A", "186#5A"}));
}

}  // namespace
}  // namespace canfleet::canopen::test_pdo
