// Every error names the file, the line, the section and the key, so a user can fix the EDS
// without a debugger. One test per error class; line numbers are counted in the inline files.
#include <gtest/gtest.h>

#include "node/canopen/eds/eds_reader.hpp"
#include "tests/unit/eds/eds_test_util.hpp"

namespace canfleet::canopen {
namespace {

using test::ExpectEdsError;

constexpr std::string_view kRecord =
    "[2090]\n"                // 1
    "ParameterName=Window\n"  // 2
    "ObjectType=0x9\n"        // 3
    "SubNumber=2\n"           // 4
    "[2090sub0]\n"            // 5
    "ParameterName=Count\n"   // 6
    "DataType=0x0005\n"       // 7
    "AccessType=ro\n"         // 8
    "DefaultValue=1\n"        // 9
    "[2090sub1]\n"            // 10
    "ParameterName=Width\n"   // 11
    "DataType=0x0007\n"       // 12
    "AccessType=rw\n";        // 13

TEST(EdsErrorTest, MessageReadsLikeACompilerDiagnostic) {
  try {
    ParseEds(std::string(kRecord) + "DefaultValue=0xZZ\n", "quad.eds");
    FAIL() << "no error";
  } catch (const EdsError& e) {
    EXPECT_STREQ(e.what(), "quad.eds:14: [2090sub1] DefaultValue: \"0xZZ\" is not a number");
  }
}

// CiA 306 v1.3 §4.6.3.2: values must be valid for their DataType.
TEST(EdsErrorTest, InvalidValuesOfKnownKeys) {
  const std::string r(kRecord);
  ExpectEdsError(r + "DefaultValue=0x100000000\n",
                 {14, "2090sub1", "DefaultValue", "out of range for UNSIGNED32"});
  ExpectEdsError(r + "LowLimit=-1\n", {14, "2090sub1", "LowLimit", "out of range for UNSIGNED32"});
  ExpectEdsError(r + "HighLimit=ten\n", {14, "2090sub1", "HighLimit", "\"ten\" is not a number"});
  ExpectEdsError(r + "PDOMapping=2\n", {14, "2090sub1", "PDOMapping", "\"2\" is out of range (0..1)"});
  ExpectEdsError(r + "ObjFlags=0x100000000\n", {14, "2090sub1", "ObjFlags", "out of range"});
  ExpectEdsError(r + "ObjectType=0x9\n",
                 {14, "2090sub1", "ObjectType", "a sub-object must be VAR or DOMAIN"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=0x0005\nAccessType=rw\nDefaultValue=300\n",
                 {5, "2000", "DefaultValue", "\"300\" is out of range for UNSIGNED8 (0..255)"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=0x0008\nAccessType=rw\nDefaultValue=1e39\n",
                 {5, "2000", "DefaultValue", "out of range for a REAL"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=0x000A\nAccessType=rw\nDefaultValue=0G\n",
                 {5, "2000", "DefaultValue", "not hex bytes"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=0x0008\nAccessType=rw\nDefaultValue=$NODEID+1\n",
                 {5, "2000", "DefaultValue", "not a number"});
}

TEST(EdsErrorTest, DataTypeAndAccessType) {
  ExpectEdsError("[2000]\nParameterName=x\nAccessType=rw\n", {1, "2000", "DataType", "missing"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=0x0005\n", {1, "2000", "AccessType", "missing"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=0x0005\nAccessType=\n",
                 {4, "2000", "AccessType", "missing"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=0x0005\nAccessType=readonly\n",
                 {4, "2000", "AccessType", "\"readonly\" is not an access type"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=0x0040\nAccessType=rw\n",
                 {3, "2000", "DataType", "0x0040 is not a supported data type"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=UNSIGNED8\nAccessType=rw\n",
                 {3, "2000", "DataType", "\"UNSIGNED8\" is not a number"});
  ExpectEdsError("[2000]\nDataType=0x0005\nAccessType=rw\n", {1, "2000", "ParameterName", "missing"});
  ExpectEdsError("[2000]\nParameterName=x\nObjectType=0x3\n",
                 {3, "2000", "ObjectType", "0x3 is not an object type"});
}

TEST(EdsErrorTest, SubObjectStructure) {
  const std::string r(kRecord);
  ExpectEdsError(r + "[2091sub1]\nParameterName=y\n", {14, "2091sub1", "", "no object section [2091]"});
  ExpectEdsError("[2090]\nParameterName=x\nObjectType=0x9\nSubNumber=3\n" + r.substr(r.find("[2090sub0]")),
                 {4, "2090", "SubNumber", "says 3 but 2 sub-object sections [2090subN] exist"});
  ExpectEdsError("[2090]\nParameterName=x\nObjectType=0x8\n",
                 {1, "2090", "SubNumber", "missing for ARRAY object"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=5\nAccessType=rw\n[2000sub0]\nParameterName=y\n",
                 {5, "2000sub0", "", "sub-object section for VAR object 2000"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=5\nAccessType=rw\nSubNumber=1\n",
                 {5, "2000", "SubNumber", "a VAR object has no sub-objects"});
  ExpectEdsError("[2000sub100]\n", {1, "2000sub100", "", "sub-index \"100\" is not a hex byte"});
}

TEST(EdsErrorTest, DuplicateSectionsAndKeys) {
  const std::string r(kRecord);
  ExpectEdsError(r + "[2090SUB01]\nParameterName=again\n",
                 {14, "2090SUB01", "", "duplicate section (first on line 10)"});
  ExpectEdsError("[2000]\nParameterName=x\n[FileInfo]\n[2000]\n",
                 {4, "2000", "", "duplicate section (first on line 1)"});
  ExpectEdsError("[FileInfo]\n[fileinfo]\n", {2, "fileinfo", "", "duplicate section"});
  ExpectEdsError("[2000]\nParameterName=x\nDataType=5\ndatatype=6\nAccessType=rw\n",
                 {4, "2000", "datatype", "duplicate key (first on line 3)"});
}

// CiA 306 v1.3 §4.6.1: SupportedObjects=n and entries 1..n naming objects that have sections.
TEST(EdsErrorTest, ObjectLists) {
  const std::string var = "[1000]\nParameterName=x\nDataType=7\nAccessType=ro\n";  // lines 1-4
  ExpectEdsError(var + "[MandatoryObjects]\nSupportedObjects=2\n1=0x1000\n2=0x1001\n",
                 {8, "MandatoryObjects", "2", "object 1001 is listed but has no section [1001]"});
  ExpectEdsError(var + "[MandatoryObjects]\nSupportedObjects=2\n1=0x1000\n",
                 {6, "MandatoryObjects", "SupportedObjects", "says 2 but 1 entries follow"});
  ExpectEdsError(var + "[OptionalObjects]\nSupportedObjects=1\n1=0x1000\n2=0x1000\n",
                 {8, "OptionalObjects", "2", "entry 2 is not in 1..1"});
  ExpectEdsError(var + "[OptionalObjects]\nSupportedObjects=1\n1=object\n",
                 {7, "OptionalObjects", "1", "\"object\" is not an object index"});
  ExpectEdsError(var + "[ManufacturerObjects]\n1=0x1000\n",
                 {5, "ManufacturerObjects", "SupportedObjects", "missing"});
}

TEST(EdsErrorTest, FileLevelSections) {
  ExpectEdsError("[FileInfo]\nFileName=a\nCreationDate=2024-03-14\n",
                 {3, "FileInfo", "CreationDate", "\"2024-03-14\" is not a date (mm-dd-yyyy)"});
  ExpectEdsError("[FileInfo]\nCreationTime=9.15\n", {2, "FileInfo", "CreationTime", "is not a time"});
  ExpectEdsError("[FileInfo]\nFileVersion=256\n", {2, "FileInfo", "FileVersion", "out of range (0..255)"});
  ExpectEdsError("[DeviceInfo]\nGranularity=65\n", {2, "DeviceInfo", "Granularity", "out of range (0..64)"});
  ExpectEdsError("[DeviceInfo]\nBaudRate_250=yes\n", {2, "DeviceInfo", "BaudRate_250", "is not a number"});
  ExpectEdsError("[DeviceInfo]\nVendorNumber=-1\n", {2, "DeviceInfo", "VendorNumber", "out of range"});
  ExpectEdsError("[DummyUsage]\nDummy0005=2\n", {2, "DummyUsage", "Dummy0005", "out of range (0..1)"});
  ExpectEdsError("[Comments]\nLines=3\nLine1=a\nLine2=b\n",
                 {2, "Comments", "Lines", "says 3 but Line3 is missing"});
}

// 254 copies of a long default would take gigabytes: the reader stops at kMaxDictionaryBytes.
TEST(EdsErrorTest, CompactSubObjCannotBlowUpMemory) {
  std::string bomb =
      "[2000]\nParameterName=bomb\nObjectType=0x8\nDataType=0x0009\nAccessType=ro\n"
      "CompactSubObj=254\nDefaultValue=" +
      std::string(kMaxDictionaryBytes / 200, 'x') + "\n";
  ExpectEdsError(bomb, {1, "2000", "", "object dictionary too large (over 64 MiB)"});
}

TEST(EdsErrorTest, BinaryGarbage) {
  ExpectEdsError("PK\x03\x04\x14", {1, "", "", "binary data (byte 0x03)"});
  ExpectEdsError("[FileInfo]\nFileName=a\nx=\x89PNG\x1A\n", {3, "", "", "binary data (byte 0x1A)"});
}

TEST(EdsErrorTest, ReadEdsNamesAFileItCannotRead) {
  try {
    ReadEds("/nonexistent/quad.eds");
    FAIL() << "no error";
  } catch (const EdsError& e) {
    EXPECT_EQ(e.file(), "/nonexistent/quad.eds");
    EXPECT_EQ(e.line(), 0u);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/quad.eds: cannot read"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace canfleet::canopen
