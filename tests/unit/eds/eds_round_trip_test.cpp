// Writing EDS and DCF files (CiA 306 v1.3) and reading them back: read -> write -> read must give
// the same dictionary and file-level information.
#include "node/canopen/eds/eds_writer.hpp"

#include <gtest/gtest.h>

#include <sstream>

#include "node/canopen/eds/eds.hpp"
#include "tests/unit/eds/eds_test_util.hpp"

namespace canfleet::canopen {
namespace {

std::string Join(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& line : lines)
    out += line + "\n";
  return out;
}

EdsFile RoundTrip(const EdsFile& file, EdsFormat format, std::string* text_out = nullptr) {
  std::ostringstream out;
  WriteEds(file, out, format);
  if (text_out) *text_out = out.str();
  return ParseEds(out.str(), "written");
}

TEST(EdsRoundTripTest, FixtureEdsSurvivesWriteAndRead) {
  auto eds = ReadEds(test::DataPath("ds401_io.eds"));
  std::string text;
  auto again = RoundTrip(eds, EdsFormat::kEds, &text);
  EXPECT_EQ(Join(DiffEdsFiles(eds, again, EdsFormat::kEds)), "");
  // The expanded CompactSubObj array reads back as ordinary sub-objects.
  EXPECT_NE(text.find("[6000sub2]\nParameterName=Read input 8-bit, inputs 9..16\n"), std::string::npos);
  EXPECT_EQ(again.od.Find(0x6000)->compact_sub_obj, 0);
}

// CiA 306 v1.3 §4.6.1: objects are listed in Mandatory/Optional/ManufacturerObjects; every object
// has its own section and every sub-object its [xxxxsubN] section.
TEST(EdsRoundTripTest, WrittenFileHasTheCiA306Layout) {
  auto eds = ReadEds(test::DataPath("ds401_io.eds"));
  std::string text = WriteEdsString(eds, EdsFormat::kEds);
  EXPECT_EQ(text.rfind("[FileInfo]\nFileName=ds401_io.eds\n", 0), 0u) << text.substr(0, 200);
  EXPECT_NE(text.find("CreationDate=03-14-2024\n"), std::string::npos);
  EXPECT_NE(text.find("[MandatoryObjects]\nSupportedObjects=3\n1=0x1000\n2=0x1001\n3=0x1018\n"),
            std::string::npos);
  EXPECT_NE(text.find("[ManufacturerObjects]\nSupportedObjects=3\n1=0x2000\n2=0x2001\n3=0x2002\n"),
            std::string::npos);
  EXPECT_NE(text.find("[OptionalObjects]\nSupportedObjects=12\n"), std::string::npos);
  EXPECT_NE(text.find("[1200sub1]\nParameterName=COB-ID client to server\nObjectType=0x7\nDataType=0x0007\n"
                      "AccessType=ro\nDefaultValue=$NODEID+0x00000600\nPDOMapping=0\n"),
            std::string::npos);
  EXPECT_NE(text.find("[2001]\nParameterName=Filter time\nObjectType=0x7\nDataType=0x0003\nAccessType=rw\n"
                      "DefaultValue=8\nPDOMapping=0\nLowLimit=-5\nHighLimit=500\nObjFlags=0x1\n"),
            std::string::npos);
  EXPECT_NE(text.find("[1018]\nParameterName=Identity object\nObjectType=0x9\nSubNumber=0x5\n"),
            std::string::npos);
  EXPECT_EQ(text.find("ParameterValue"), std::string::npos);  // an EDS has no configured values
  EXPECT_EQ(text.find("[DeviceComissioning]"), std::string::npos);
}

TEST(EdsRoundTripTest, WritingIsStable) {
  auto eds = ReadEds(test::DataPath("ds401_io.eds"));
  std::string first = WriteEdsString(eds, EdsFormat::kEds);
  EXPECT_EQ(WriteEdsString(ParseEds(first, "first"), EdsFormat::kEds), first);
}

// CiA 306 v1.3 §5: a DCF adds [DeviceComissioning] and ParameterValue for each sub-object.
TEST(EdsRoundTripTest, FixtureDcfSurvivesWriteAndRead) {
  auto dcf = ReadEds(test::DataPath("ds401_io_node5.dcf"));
  std::string text;
  auto again = RoundTrip(dcf, EdsFormat::kDcf, &text);
  EXPECT_EQ(Join(DiffEdsFiles(dcf, again, EdsFormat::kDcf)), "");
  EXPECT_NE(text.find("[DeviceComissioning]\nNodeID=5\nNodeName=io-left\nBaudrate=250\n"), std::string::npos);
  EXPECT_NE(text.find("DefaultValue=$NODEID+0x00000180\nPDOMapping=0\nParameterValue=0x40000185\n"),
            std::string::npos);
  EXPECT_NE(text.find("LastEDS=ds401_io.eds\n"), std::string::npos);
}

// An EDS becomes a DCF once a node-ID is chosen: values are the defaults with it applied.
TEST(EdsRoundTripTest, EdsWrittenAsDcfKeepsValues) {
  auto eds = ReadEds(test::DataPath("ds401_io.eds"));
  eds.dcf_node_id = 0x22;
  eds.dcf_baudrate_kbit = 500;
  eds.od.RestoreDefaults(0x1000, 0xFFFF, 0x22);
  ASSERT_EQ(eds.od.Find(0x1400, 1)->value, EncodeLe<std::uint32_t>(0x222));
  auto again = RoundTrip(eds, EdsFormat::kDcf);
  EXPECT_EQ(Join(DiffEdsFiles(eds, again, EdsFormat::kDcf)), "");
  EXPECT_EQ(again.od.Find(0x1400, 1)->value, EncodeLe<std::uint32_t>(0x222));
}

TEST(EdsRoundTripTest, NodeRelativeLimitsAreKept) {
  auto eds = ParseEds(
      "[2000]\nParameterName=x\nDataType=0x0007\nAccessType=rw\nLowLimit=$NODEID+0x180\n"
      "HighLimit=0x1FF\nDefaultValue=$NODEID+0x180\n",
      "t.eds");
  EXPECT_EQ(eds.node_id_limits.at({0x2000, 0}), (NodeIdLimits{true, false}));
  EXPECT_EQ(eds.od.Find(0x2000, 0)->low_limit, EncodeLe<std::uint32_t>(0x180));
  std::string text;
  auto again = RoundTrip(eds, EdsFormat::kEds, &text);
  EXPECT_NE(text.find("LowLimit=$NODEID+0x00000180\nHighLimit=0x000001FF\n"), std::string::npos);
  EXPECT_EQ(Join(DiffEdsFiles(eds, again, EdsFormat::kEds)), "");
}

// Found by the fuzzer: tabs inside a value are read, so they must be written.
TEST(EdsRoundTripTest, TabsInsideValues) {
  auto eds = ParseEds(
      "[DeviceInfo]\nVendorName=a\t\tb\n[2000]\nParameterName=x\ty\nDataType=9\nAccessType=ro\n"
      "DefaultValue=p\tq\n",
      "t.eds");
  EXPECT_EQ(eds.device_info.vendor_name, "a\t\tb");
  auto again = RoundTrip(eds, EdsFormat::kDcf);
  EXPECT_EQ(Join(DiffEdsFiles(eds, again, EdsFormat::kDcf)), "");
}

// A dictionary built in code (a generic node's) can be written and read back.
TEST(EdsRoundTripTest, DictionaryBuiltInCode) {
  EdsFile file;
  file.od.AddVar(0x1000, "Device type", DataType::kUnsigned32, Access::kRo, EncodeLe<std::uint32_t>(0x191));
  file.od.AddVar(0x1001, "Error register", DataType::kUnsigned8, Access::kRo, {0}, true);
  auto& limited =
      file.od.AddVar(0x2090, "Window", DataType::kInteger64, Access::kRw, EncodeLe<std::int64_t>(-7));
  limited.low_limit = EncodeLe<std::int64_t>(std::numeric_limits<std::int64_t>::min());
  limited.high_limit = EncodeLe<std::int64_t>(1000);
  file.od.AddVar(0x2091, "Ratio", DataType::kReal64, Access::kRw, EncodeLe(1.0 / 3.0));
  file.od.AddVar(0x2092, "Blob", DataType::kDomain, Access::kWo, {});
  file.od.AddVar(0x2093, "Label", DataType::kVisibleString, Access::kRw, ToBytes(""));
  auto again = RoundTrip(file, EdsFormat::kDcf);
  EXPECT_EQ(Join(DiffEdsFiles(file, again, EdsFormat::kDcf)), "");
}

TEST(EdsRoundTripTest, WriterRefusesWhatCannotBeSpelled) {
  EdsFile file;
  file.od.AddVar(0x2000, "two\nlines", DataType::kUnsigned8, Access::kRw, {0});
  EXPECT_THROW(WriteEdsString(file, EdsFormat::kEds), EdsError);

  EdsFile wrong_size;
  wrong_size.od.AddVar(0x2000, "x", DataType::kUnsigned16, Access::kRw, {0});
  try {
    WriteEdsString(wrong_size, EdsFormat::kEds);
    FAIL() << "no error";
  } catch (const EdsError& e) {
    EXPECT_EQ(e.section(), "2000");
    EXPECT_EQ(e.key(), "DefaultValue");
    EXPECT_NE(e.detail().find("1 bytes for UNSIGNED16"), std::string::npos) << e.what();
  }

  EdsFile no_sub0;
  Object obj;
  obj.index = 0x2000;
  obj.name = "x";
  no_sub0.od.Add(std::move(obj));
  EXPECT_THROW(WriteEdsString(no_sub0, EdsFormat::kEds), EdsError);

  EdsFile dcf_value;
  dcf_value.od.AddVar(0x2000, "s", DataType::kVisibleString, Access::kRw, ToBytes("ok")).value =
      ToBytes(" lead");
  EXPECT_NO_THROW(WriteEdsString(dcf_value, EdsFormat::kEds));  // an EDS has no values
  EXPECT_THROW(WriteEdsString(dcf_value, EdsFormat::kDcf), EdsError);
}

// The comparison helper must see every field the round trip has to keep.
TEST(EdsCompareTest, ReportsEachDifference) {
  auto a = ReadEds(test::DataPath("ds401_io.eds"));
  auto b = a;
  EXPECT_TRUE(DiffEdsFiles(a, b, EdsFormat::kDcf).empty());
  b.od.Find(0x1018, 2)->name = "Product";
  b.od.Find(0x1001, 0)->pdo_mappable = false;
  b.od.Find(0x1400, 1)->default_adds_node_id = false;
  b.od.Find(0x1017, 0)->value = EncodeLe<std::uint16_t>(1);
  b.od.objects().erase(0x2002);
  b.device_info.granularity = 0;
  auto diffs = DiffEdsFiles(a, b, EdsFormat::kDcf);
  EXPECT_EQ(Join(diffs),
            "1001sub0 PDOMapping: 1 != 0\n"
            "1017sub0 value: E803 != 0100\n"
            "1018sub2 ParameterName: \"Product code\" != \"Product\"\n"
            "1400sub1 $NODEID default: 1 != 0\n"
            "2002 missing from the second dictionary\n"
            "DeviceInfo Granularity: 8 != 0\n");
  EXPECT_EQ(DiffObjectDictionaries(a.od, b.od, false).size(), 4u);  // values not compared
}

TEST(EdsWriterTest, StampFileInfoUsesCiA306Spelling) {
  FileInfo info;
  using namespace std::chrono;
  auto when = sys_days{year{2024} / March / 5} + hours{13} + minutes{7};
  StampFileInfo(info, when);
  EXPECT_EQ(info.creation_date, "03-05-2024");
  EXPECT_EQ(info.creation_time, "01:07PM");
  EXPECT_EQ(info.modification_date, "03-05-2024");
  StampFileInfo(info, sys_days{year{2025} / January / 31} + minutes{59});
  EXPECT_EQ(info.creation_date, "03-05-2024");  // kept
  EXPECT_EQ(info.modification_time, "12:59AM");
  EXPECT_EQ(info.modification_date, "01-31-2025");
}

TEST(EdsWriterTest, ObjectLists) {
  EXPECT_EQ(ObjectListFor(0x1000), EdsObjectList::kMandatory);
  EXPECT_EQ(ObjectListFor(0x1018), EdsObjectList::kMandatory);
  EXPECT_EQ(ObjectListFor(0x1017), EdsObjectList::kOptional);
  EXPECT_EQ(ObjectListFor(0x2000), EdsObjectList::kManufacturer);
  EXPECT_EQ(ObjectListFor(0x5FFF), EdsObjectList::kManufacturer);
  EXPECT_EQ(ObjectListFor(0x6000), EdsObjectList::kOptional);
  EXPECT_EQ(ObjectListFor(0x0007), EdsObjectList::kOptional);
}

}  // namespace
}  // namespace canfleet::canopen
