// Reading a whole EDS: the fixture data/ds401_io.eds (a small CiA 401 I/O module) and inline
// files for each syntax feature of CiA 306 v1.3.
#include "node/canopen/eds/eds_reader.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "tests/unit/eds/eds_test_util.hpp"

namespace canfleet::canopen {
namespace {

class Ds401FixtureTest : public ::testing::Test {
 protected:
  void SetUp() override { eds = ReadEds(test::DataPath("ds401_io.eds")); }

  const SubObject& Sub(std::uint16_t index, std::uint8_t sub) {
    const SubObject* found = eds.od.Find(index, sub);
    EXPECT_NE(found, nullptr) << std::hex << index << "sub" << int{sub};
    static const SubObject kMissing{};
    return found ? *found : kMissing;
  }

  EdsFile eds;
};

// CiA 306 v1.3 §4.3 [FileInfo]: kept as written so the file can be written back.
TEST_F(Ds401FixtureTest, FileInfo) {
  const FileInfo& f = eds.file_info;
  EXPECT_EQ(f.file_name, "ds401_io.eds");
  EXPECT_EQ(f.file_version, 1);
  EXPECT_EQ(f.file_revision, 2);
  EXPECT_EQ(f.eds_version, "4.0");
  EXPECT_EQ(f.description, "8 DI / 8 DO / 2 AI test module");
  EXPECT_EQ(f.creation_time, "09:15AM");
  EXPECT_EQ(f.creation_date, "03-14-2024");
  EXPECT_EQ(f.modification_time, "4:05 pm");
  EXPECT_EQ(f.modified_by, "canfleet");
}

// CiA 306 v1.3 §4.4 [DeviceInfo].
TEST_F(Ds401FixtureTest, DeviceInfo) {
  const DeviceInfo& d = eds.device_info;
  EXPECT_EQ(d.vendor_name, "canfleet test devices");
  EXPECT_EQ(d.vendor_number, 0x3E8u);
  EXPECT_EQ(d.product_name, "IO-401");
  EXPECT_EQ(d.product_number, 0x191u);
  EXPECT_EQ(d.revision_number, 0x00010002u);
  EXPECT_EQ(d.order_code, "IO401-A");
  EXPECT_EQ(d.baud_rates_kbit, (std::set<std::uint16_t>{50, 125, 250, 500, 1000}));
  EXPECT_FALSE(d.simple_boot_up_master);
  EXPECT_TRUE(d.simple_boot_up_slave);
  EXPECT_EQ(d.granularity, 8);
  EXPECT_EQ(d.nr_of_rx_pdo, 1);
  EXPECT_EQ(d.nr_of_tx_pdo, 1);
  EXPECT_TRUE(d.lss_supported);
  EXPECT_FALSE(d.compact_pdo.has_value());
}

// CiA 306 v1.3 §4.5 [DummyUsage], and the [Comments] section (Lines=n, Line1..Linen).
TEST_F(Ds401FixtureTest, DummyUsageAndComments) {
  EXPECT_EQ(eds.dummy_usage, 0b11111100u);  // Dummy0002..Dummy0007
  ASSERT_EQ(eds.comments.size(), 2u);
  EXPECT_EQ(eds.comments[1], "Analog inputs (6401h) are signed 16-bit counts.");
  EXPECT_FALSE(eds.dcf_node_id.has_value());
}

TEST_F(Ds401FixtureTest, AllListedObjectsAreRead) {
  std::vector<std::uint16_t> indexes;
  for (const auto& [index, obj] : eds.od.objects())
    indexes.push_back(index);
  EXPECT_EQ(indexes, (std::vector<std::uint16_t>{0x1000, 0x1001, 0x1003, 0x1008, 0x1017, 0x1018, 0x1021,
                                                 0x1200, 0x1400, 0x1600, 0x1800, 0x1A00, 0x2000, 0x2001,
                                                 0x2002, 0x6000, 0x6200, 0x6401}));
}

// CiA 306 v1.3 §4.6.3.2: a VAR is one sub-object at sub-index 0 carrying the object's keys.
TEST_F(Ds401FixtureTest, VarObjects) {
  const Object* obj = eds.od.Find(0x1000);
  ASSERT_NE(obj, nullptr);
  EXPECT_EQ(obj->name, "Device type");
  EXPECT_EQ(obj->code, ObjectCode::kVar);
  ASSERT_EQ(obj->subs.size(), 1u);
  const SubObject& sub = Sub(0x1000, 0);
  EXPECT_EQ(sub.name, "Device type");
  EXPECT_EQ(sub.type, DataType::kUnsigned32);
  EXPECT_EQ(sub.access, Access::kRo);
  EXPECT_FALSE(sub.pdo_mappable);
  EXPECT_EQ(sub.default_value, EncodeLe<std::uint32_t>(0x000F0191));
  EXPECT_EQ(sub.value, sub.default_value);  // an EDS has no ParameterValue: value = default
  EXPECT_TRUE(Sub(0x1001, 0).pdo_mappable);
}

// CiA 306 v1.3 §4.6.3.2: RECORD/ARRAY objects describe each sub-index in [xxxxsubN].
TEST_F(Ds401FixtureTest, RecordAndArraySubObjects) {
  const Object* identity = eds.od.Find(0x1018);
  ASSERT_NE(identity, nullptr);
  EXPECT_EQ(identity->code, ObjectCode::kRecord);
  EXPECT_EQ(identity->subs.size(), 5u);
  EXPECT_EQ(Sub(0x1018, 0).access, Access::kConst);
  EXPECT_EQ(Sub(0x1018, 0).default_value, Bytes{4});
  EXPECT_EQ(Sub(0x1018, 2).name, "Product code");
  EXPECT_EQ(Sub(0x1018, 2).default_value, EncodeLe<std::uint32_t>(0x191));
  EXPECT_EQ(eds.od.Find(0x1003)->code, ObjectCode::kArray);
  EXPECT_EQ(Sub(0x1003, 2).type, DataType::kUnsigned32);
  // 1800h skips sub4 (reserved); SubNumber counts the sections that exist.
  EXPECT_EQ(eds.od.Find(0x1800)->subs.size(), 6u);
  EXPECT_EQ(eds.od.Find(0x1800, 4), nullptr);
  EXPECT_NE(eds.od.Find(0x1800, 5), nullptr);
}

// CiA 306 v1.3 §4.6.3.2: "$NODEID+x" and "x+$NODEID" defaults; the constant is kept.
TEST_F(Ds401FixtureTest, NodeIdDefaults) {
  EXPECT_TRUE(Sub(0x1200, 1).default_adds_node_id);
  EXPECT_EQ(Sub(0x1200, 1).default_value, EncodeLe<std::uint32_t>(0x600));
  EXPECT_TRUE(Sub(0x1200, 2).default_adds_node_id);
  EXPECT_EQ(Sub(0x1200, 2).default_value, EncodeLe<std::uint32_t>(0x580));
  EXPECT_EQ(Sub(0x1400, 1).default_value, EncodeLe<std::uint32_t>(0x200));
  EXPECT_EQ(Sub(0x1800, 1).default_value, EncodeLe<std::uint32_t>(0x40000180));
  EXPECT_EQ(Sub(0x1800, 1).DefaultFor(5), EncodeLe<std::uint32_t>(0x40000185));
  EXPECT_FALSE(Sub(0x1800, 2).default_adds_node_id);
}

TEST_F(Ds401FixtureTest, LimitsIncludingTwosComplementHex) {
  EXPECT_EQ(Sub(0x1600, 0).low_limit, Bytes{0});
  EXPECT_EQ(Sub(0x1600, 0).high_limit, Bytes{8});
  EXPECT_EQ(Sub(0x6401, 1).low_limit, EncodeLe<std::int16_t>(-32000));
  EXPECT_EQ(Sub(0x6401, 2).low_limit, EncodeLe<std::int16_t>(-32000));  // 0x8300
  EXPECT_EQ(Sub(0x6401, 2).high_limit, EncodeLe<std::int16_t>(32000));  // 0x7D00
  EXPECT_EQ(Sub(0x6401, 2).default_value, EncodeLe<std::int16_t>(-1));
  EXPECT_FALSE(Sub(0x1000, 0).low_limit.has_value());
}

// CiA 306 v1.3 §4.1: keys are not case-sensitive; values may be followed by blanks and comments.
TEST_F(Ds401FixtureTest, KeysInAnyCaseAndCommentsAfterNumbers) {
  const SubObject& scale = Sub(0x2000, 0);
  EXPECT_EQ(eds.od.Find(0x2000)->name, "Analog scale factor");
  EXPECT_EQ(scale.type, DataType::kReal32);
  EXPECT_EQ(scale.access, Access::kRw);  // "RW"
  EXPECT_EQ(scale.default_value, EncodeLe(0.125f));
  EXPECT_EQ(Sub(0x1017, 0).default_value, EncodeLe<std::uint16_t>(1000));  // "1000   ; ms"
}

TEST_F(Ds401FixtureTest, OctalSignsAndObjFlags) {
  const SubObject& filter = Sub(0x2001, 0);
  EXPECT_EQ(filter.type, DataType::kInteger16);
  EXPECT_EQ(filter.default_value, EncodeLe<std::int16_t>(8));  // "010" is octal
  EXPECT_EQ(filter.low_limit, EncodeLe<std::int16_t>(-5));
  EXPECT_EQ(filter.high_limit, EncodeLe<std::int16_t>(500));  // "+500"
  EXPECT_EQ(filter.obj_flags, 1u);
  EXPECT_EQ(eds.od.Find(0x2001)->obj_flags, 1u);
}

// VISIBLE_STRING defaults are text (';' included); OCTET_STRING and DOMAIN defaults are hex.
TEST_F(Ds401FixtureTest, StringsOctetStringsAndDomains) {
  EXPECT_EQ(Sub(0x1008, 0).type, DataType::kVisibleString);
  EXPECT_EQ(Sub(0x1008, 0).default_value, ToBytes("IO-401; rev B"));
  EXPECT_EQ(Sub(0x2002, 0).default_value, (Bytes{0x01, 0x02, 0xA0, 0xFF}));
  const Object* store = eds.od.Find(0x1021);
  EXPECT_EQ(store->code, ObjectCode::kDomain);
  EXPECT_EQ(Sub(0x1021, 0).type, DataType::kDomain);
  EXPECT_EQ(Sub(0x1021, 0).access, Access::kRo);
  EXPECT_TRUE(Sub(0x1021, 0).default_value.empty());
}

TEST(EdsReaderTest, ParseEdsReadsTheSameAsReadEds) {
  std::ifstream in(test::DataPath("ds401_io.eds"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto parsed = ParseEds(text, "ds401_io.eds");
  EXPECT_EQ(parsed.od.objects().size(), ReadEds(test::DataPath("ds401_io.eds")).od.objects().size());
}

// CiA 306 v1.3 §4.6.3.2: an object section without ObjectType is a VAR.
// A missing or empty DefaultValue of a number is zero; PDOMapping defaults to 0.
TEST(EdsReaderTest, DefaultsForMissingKeys) {
  auto eds = ParseEds(
      "[2000]\nParameterName=a\nDataType=0x0007\nAccessType=rw\n"
      "[2001]\nParameterName=b\nDataType=0x0004\nAccessType=rw\nDefaultValue=\n",
      "t.eds");
  EXPECT_EQ(eds.od.Find(0x2000)->code, ObjectCode::kVar);
  EXPECT_EQ(eds.od.Find(0x2000, 0)->default_value, Bytes(4, 0));
  EXPECT_FALSE(eds.od.Find(0x2000, 0)->pdo_mappable);
  EXPECT_EQ(eds.od.Find(0x2001, 0)->default_value, Bytes(4, 0));
}

// CiA 306 v1.3 §4.1: section names are not case-sensitive; the object lists are optional for us
// (a file without them still gives a usable dictionary); index sections may omit leading zeros.
TEST(EdsReaderTest, SectionNamesInAnyCase) {
  auto eds = ParseEds(
      "[fileinfo]\nFileName=x.eds\n[1018]\nParameterName=Identity\nObjectType=9\nSubNumber=1\n"
      "[1018SUB0]\nParameterName=n\nDataType=5\nAccessType=ro\nDefaultValue=1\n"
      "[a]\nParameterName=Dummy10\nDataType=7\nAccessType=ro\n",
      "t.eds");
  EXPECT_EQ(eds.file_info.file_name, "x.eds");
  EXPECT_EQ(eds.od.Find(0x1018, 0)->default_value, Bytes{1});
  EXPECT_NE(eds.od.Find(0x000A), nullptr);
}

// Unknown sections and keys are ignored so that vendor extensions do not stop a load.
TEST(EdsReaderTest, UnknownSectionsAndKeysAreIgnored) {
  auto eds = ParseEds(
      "[Tools]\nAnything=goes here\n[2000]\nParameterName=a\nDataType=0x0005\nAccessType=ro\n"
      "StorageLocation=RAM\nVendorKey=???\n[2000ObjectLinks]\nObjectLinks=0\n[Added]\nx=y\n",
      "t.eds");
  EXPECT_EQ(eds.od.objects().size(), 1u);
  EXPECT_EQ(eds.od.Find(0x2000, 0)->type, DataType::kUnsigned8);
}

// CiA 306 v1.3 §4.6.3.2: DataType is optional for DOMAIN objects (ObjectType=2); so, for us, is
// AccessType (rw).
TEST(EdsReaderTest, DomainObjectsNeedNoDataTypeOrAccessType) {
  auto eds = ParseEds("[1F50]\nParameterName=Program data\nObjectType=0x2\n", "t.eds");
  const SubObject* sub = eds.od.Find(0x1F50, 0);
  ASSERT_NE(sub, nullptr);
  EXPECT_EQ(sub->type, DataType::kDomain);
  EXPECT_EQ(sub->access, Access::kRw);
}

TEST(EdsReaderTest, DefTypeAndDefStructObjects) {
  auto eds = ParseEds(
      "[0007]\nParameterName=UNSIGNED32\nObjectType=0x5\nDataType=0x0007\nAccessType=ro\n"
      "DefaultValue=32\n"
      "[0020]\nParameterName=PDO_COMM_PAR\nObjectType=0x6\nSubNumber=1\n"
      "[0020sub0]\nParameterName=n\nDataType=0x0005\nAccessType=ro\nDefaultValue=6\n",
      "t.eds");
  EXPECT_EQ(eds.od.Find(0x0007)->code, ObjectCode::kDefType);
  EXPECT_EQ(eds.od.Find(0x0007, 0)->default_value, EncodeLe<std::uint32_t>(32));
  EXPECT_EQ(eds.od.Find(0x0020)->code, ObjectCode::kDefStruct);
  EXPECT_EQ(eds.od.Find(0x0020, 0)->default_value, Bytes{6});
}

// All CiA 301 basic types with fixed sizes encode in their own width.
TEST(EdsReaderTest, EveryFixedSizeTypeEncodesInItsWidth) {
  const std::pair<int, std::size_t> types[] = {
      {0x01, 1}, {0x02, 1}, {0x03, 2}, {0x04, 4}, {0x05, 1}, {0x06, 2}, {0x07, 4},
      {0x08, 4}, {0x0C, 6}, {0x0D, 6}, {0x10, 3}, {0x11, 8}, {0x12, 5}, {0x13, 6},
      {0x14, 7}, {0x15, 8}, {0x16, 3}, {0x18, 5}, {0x19, 6}, {0x1A, 7}, {0x1B, 8}};
  for (auto [code, size] : types) {
    auto text =
        "[2000]\nParameterName=x\nDataType=" + std::to_string(code) + "\nAccessType=rw\nDefaultValue=1\n";
    auto eds = ParseEds(text, "t.eds");
    EXPECT_EQ(eds.od.Find(0x2000, 0)->default_value.size(), size) << code;
  }
}

}  // namespace
}  // namespace canfleet::canopen
