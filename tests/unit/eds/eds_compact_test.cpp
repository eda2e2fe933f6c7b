// CiA 306 v1.3 compact storage of sub-objects (§4.6.3.3): CompactSubObj=n on an ARRAY stands for
// sub0 (number of entries, UNSIGNED8, ro) and sub1..n described by the object section itself;
// [xxxxName] gives sub-object names and [xxxxValue] their values.
#include <gtest/gtest.h>

#include "node/canopen/eds/eds_reader.hpp"
#include "tests/unit/eds/eds_test_util.hpp"

namespace canfleet::canopen {
namespace {

using test::ExpectEdsError;

TEST(EdsCompactTest, FixtureArrayIsExpanded) {
  auto eds = ReadEds(test::DataPath("ds401_io.eds"));
  const Object* inputs = eds.od.Find(0x6000);
  ASSERT_NE(inputs, nullptr);
  EXPECT_EQ(inputs->code, ObjectCode::kArray);
  EXPECT_EQ(inputs->compact_sub_obj, 2);
  ASSERT_EQ(inputs->subs.size(), 3u);
  const SubObject& count = inputs->subs.at(0);
  EXPECT_EQ(count.name, "NrOfObjects");
  EXPECT_EQ(count.type, DataType::kUnsigned8);
  EXPECT_EQ(count.access, Access::kRo);
  EXPECT_EQ(count.default_value, Bytes{2});
  EXPECT_EQ(count.value, Bytes{2});
  const SubObject& first = inputs->subs.at(1);
  EXPECT_EQ(first.name, "Read input 8-bit1");
  EXPECT_EQ(first.type, DataType::kUnsigned8);
  EXPECT_EQ(first.access, Access::kRo);
  EXPECT_TRUE(first.pdo_mappable);
  EXPECT_EQ(first.default_value, Bytes{0});
  EXPECT_EQ(inputs->subs.at(2).name, "Read input 8-bit, inputs 9..16");  // from [6000Name]
  const SubObject* output = eds.od.Find(0x6200, 1);
  ASSERT_NE(output, nullptr);
  EXPECT_EQ(output->access, Access::kRww);
  EXPECT_EQ(output->index, 0x6200);
  EXPECT_EQ(output->sub_index, 1);
}

constexpr std::string_view kCompactHeader =
    "[2100]\n"                      // 1
    "ParameterName=Channel\n"       // 2
    "ObjectType=0x8\n"              // 3
    "DataType=0x0007\n"             // 4
    "AccessType=rw\n"               // 5
    "DefaultValue=$NODEID+0x100\n"  // 6
    "LowLimit=0x10\n"               // 7
    "CompactSubObj=3\n";            // 8

TEST(EdsCompactTest, EverySubObjectGetsTheObjectKeys) {
  auto eds = ParseEds(kCompactHeader, "t.eds");
  for (std::uint8_t i = 1; i <= 3; ++i) {
    const SubObject* sub = eds.od.Find(0x2100, i);
    ASSERT_NE(sub, nullptr);
    EXPECT_EQ(sub->name, "Channel" + std::to_string(i));
    EXPECT_TRUE(sub->default_adds_node_id);
    EXPECT_EQ(sub->default_value, EncodeLe<std::uint32_t>(0x100));
    EXPECT_EQ(sub->low_limit, EncodeLe<std::uint32_t>(0x10));
  }
}

TEST(EdsCompactTest, NameAndValueSections) {
  auto eds = ParseEds(std::string(kCompactHeader) +
                          "[2100Name]\nNrOfEntries=2\n1=First channel\n3=Last channel\n"
                          "[2100Value]\nNrOfEntries=2\n1=0x55\n2=$NODEID+0x200\n"
                          "[DeviceComissioning]\nNodeID=4\n",
                      "t.dcf");
  EXPECT_EQ(eds.od.Find(0x2100, 1)->name, "First channel");
  EXPECT_EQ(eds.od.Find(0x2100, 2)->name, "Channel2");
  EXPECT_EQ(eds.od.Find(0x2100, 3)->name, "Last channel");
  // [xxxxValue] holds current values (DCF); defaults stay the object's DefaultValue.
  EXPECT_EQ(eds.od.Find(0x2100, 1)->value, EncodeLe<std::uint32_t>(0x55));
  EXPECT_EQ(eds.od.Find(0x2100, 2)->value, EncodeLe<std::uint32_t>(0x204));
  EXPECT_EQ(eds.od.Find(0x2100, 3)->value, EncodeLe<std::uint32_t>(0x104));  // default + NodeID
  EXPECT_EQ(eds.od.Find(0x2100, 1)->default_value, EncodeLe<std::uint32_t>(0x100));
}

TEST(EdsCompactTest, CompactSubObjErrors) {
  const std::string h(kCompactHeader);
  ExpectEdsError(h + "SubNumber=4\n", {9, "2100", "SubNumber", "not allowed together with CompactSubObj"});
  ExpectEdsError(h + "[2100sub1]\nParameterName=x\n", {9, "2100sub1", "", "which has CompactSubObj"});
  ExpectEdsError(h + "[2100Name]\nNrOfEntries=1\n4=x\n", {11, "2100Name", "4", "not in 1..3"});
  ExpectEdsError(h + "[2100Name]\nNrOfEntries=2\n1=x\n", {10, "2100Name", "NrOfEntries", "says 2 but 1"});
  ExpectEdsError(h + "[2100Name]\n1=x\n", {9, "2100Name", "NrOfEntries", "missing"});
  ExpectEdsError(h + "[2100Value]\nNrOfEntries=1\n1=0x1FFFFFFFF\n", {11, "2100Value", "1", "out of range"});
  ExpectEdsError(h + "[2100Value]\nNrOfEntries=1\n1=$NODEID\n",
                 {11, "2100Value", "1", "$NODEID needs [DeviceComissioning] NodeID"});
  ExpectEdsError(h + "[2200Name]\nNrOfEntries=0\n", {9, "2200Name", "", "no object section [2200]"});
  ExpectEdsError("[2000]\nParameterName=x\nObjectType=0x8\nSubNumber=0\n[2000Name]\nNrOfEntries=0\n",
                 {5, "2000Name", "", "has no CompactSubObj"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=5\nAccessType=ro\nCompactSubObj=2\n",
                 {5, "2000", "CompactSubObj", "only ARRAY and RECORD"});
  ExpectEdsError("[2000]\nParameterName=x\nObjectType=0x8\nAccessType=ro\nCompactSubObj=2\n",
                 {1, "2000", "DataType", "missing"});
  ExpectEdsError("[2000]\nParameterName=x\nObjectType=0x8\nDataType=5\nAccessType=ro\nCompactSubObj=255\n",
                 {6, "2000", "CompactSubObj", "out of range (0..254)"});
}

}  // namespace
}  // namespace canfleet::canopen
