// SDO values as text (orchestrator/control/sdo_value.hpp): every cocomm type both ways, the limits
// of each integer type, and the messages for text that does not fit.
#include "orchestrator/control/sdo_value.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace canfleet::control {
namespace {

using Bytes = std::vector<std::uint8_t>;

struct Case {
  const char* type;
  const char* text;
  Bytes bytes;
  const char* shown;  ///< what FormatSdoValue gives back for `bytes`
};

// CiA 301 §7.1.4: every basic data type is transferred little-endian; integers two's complement,
// reals IEEE 754.
const Case kCases[] = {
    {"b", "true", {0x01}, "true"},
    {"b", "0", {0x00}, "false"},
    {"u8", "0", {0x00}, "0"},
    {"u8", "255", {0xFF}, "255"},
    {"u8", "0xFF", {0xFF}, "255"},
    {"u16", "1000", {0xE8, 0x03}, "1000"},
    {"u16", "0x3E8", {0xE8, 0x03}, "1000"},
    {"u16", "65535", {0xFF, 0xFF}, "65535"},
    {"u32", "4294967295", {0xFF, 0xFF, 0xFF, 0xFF}, "4294967295"},
    {"u32", "0x60120208", {0x08, 0x02, 0x12, 0x60}, "1611792904"},
    {"u64", "18446744073709551615", Bytes(8, 0xFF), "18446744073709551615"},
    {"u64", "0x0102030405060708", {8, 7, 6, 5, 4, 3, 2, 1}, "72623859790382856"},
    {"i8", "-128", {0x80}, "-128"},
    {"i8", "127", {0x7F}, "127"},
    {"i8", "-1", {0xFF}, "-1"},
    {"i16", "-5", {0xFB, 0xFF}, "-5"},
    {"i16", "-32768", {0x00, 0x80}, "-32768"},
    {"i16", "32767", {0xFF, 0x7F}, "32767"},
    {"i16", "-0x10", {0xF0, 0xFF}, "-16"},
    {"i32", "-2147483648", {0x00, 0x00, 0x00, 0x80}, "-2147483648"},
    {"i32", "+7", {0x07, 0, 0, 0}, "7"},
    {"i64", "-9223372036854775808", {0, 0, 0, 0, 0, 0, 0, 0x80}, "-9223372036854775808"},
    {"i64", "9223372036854775807", {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x7F}, "9223372036854775807"},
    {"r32", "1.5", {0x00, 0x00, 0xC0, 0x3F}, "1.5"},
    {"r32", "-2e3", {0x00, 0x00, 0xFA, 0xC4}, "-2000"},
    {"r64", "1.5", {0, 0, 0, 0, 0, 0, 0xF8, 0x3F}, "1.5"},
    {"r64", "0.1", {0x9A, 0x99, 0x99, 0x99, 0x99, 0x99, 0xB9, 0x3F}, "0.1"},
    {"vs", "hello", {'h', 'e', 'l', 'l', 'o'}, "hello"},
    {"vs", "", {}, ""},
    {"os", "0a0b0c", {0x0A, 0x0B, 0x0C}, "0A 0B 0C"},
    {"os", "0A 0B 0C", {0x0A, 0x0B, 0x0C}, "0A 0B 0C"},
    {"d", "deadBEEF", {0xDE, 0xAD, 0xBE, 0xEF}, "DE AD BE EF"},
    {"", "01 02", {0x01, 0x02}, "01 02"},
};

TEST(SdoValue, EveryTypeEncodesLittleEndianAndFormatsBack) {
  for (const Case& c : kCases) {
    SCOPED_TRACE(std::string(c.type) + " \"" + c.text + "\"");
    EXPECT_EQ(EncodeSdoValue(c.type, c.text), c.bytes);
    EXPECT_EQ(FormatSdoValue(c.type, c.bytes), c.shown);
    // What is shown encodes back to the same bytes.
    EXPECT_EQ(EncodeSdoValue(c.type, FormatSdoValue(c.type, c.bytes)), c.bytes);
  }
}

TEST(SdoValue, IntegerLimitsAreCheckedWithTheRangeInTheMessage) {
  struct Bad {
    const char* type;
    const char* text;
    const char* message;
  };
  const Bad kBad[] = {
      {"u8", "256", "u8 value \"256\" is out of range (0..255)"},
      {"u8", "0x100", "u8 value \"0x100\" is out of range (0..255)"},
      {"u8", "-1", "u8 value \"-1\" is out of range (0..255)"},
      {"u16", "65536", "u16 value \"65536\" is out of range (0..65535)"},
      {"u32", "4294967296", "u32 value \"4294967296\" is out of range (0..4294967295)"},
      {"u64", "18446744073709551616",
       "u64 value \"18446744073709551616\" is out of range (0..18446744073709551615)"},
      {"i8", "128", "i8 value \"128\" is out of range (-128..127)"},
      {"i8", "-129", "i8 value \"-129\" is out of range (-128..127)"},
      {"i16", "32768", "i16 value \"32768\" is out of range (-32768..32767)"},
      {"i32", "-2147483649", "i32 value \"-2147483649\" is out of range (-2147483648..2147483647)"},
      {"i64", "9223372036854775808",
       "i64 value \"9223372036854775808\" is out of range (-9223372036854775808..9223372036854775807)"},
  };
  for (const Bad& b : kBad) {
    SCOPED_TRACE(std::string(b.type) + " \"" + b.text + "\"");
    try {
      EncodeSdoValue(b.type, b.text);
      ADD_FAILURE() << "accepted";
    } catch (const SdoValueError& e) {
      EXPECT_STREQ(e.what(), b.message);
    }
  }
}

TEST(SdoValue, TextThatIsNotAValueIsRefusedNamingTypeAndText) {
  const std::pair<const char*, const char*> kBad[] = {
      {"u16", "abc"}, {"u16", ""},    {"u16", "1.5"}, {"u16", "0x"},  {"u16", "12 34"}, {"i8", "--1"},
      {"i8", "- 1"},  {"b", "maybe"}, {"b", "2"},     {"r32", "one"}, {"r32", "1.5x"},  {"r64", ""},
      {"os", "0g"},   {"os", "abc"},  {"os", "a b"},  {"d", "0x01"},
  };
  for (const auto& [type, text] : kBad) {
    SCOPED_TRACE(std::string(type) + " \"" + text + "\"");
    try {
      EncodeSdoValue(type, text);
      ADD_FAILURE() << "accepted";
    } catch (const SdoValueError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string(type) + " value \"" + text + "\""), std::string::npos)
          << e.what();
    }
  }
}

TEST(SdoValue, RealsOutsideTheirTypeAreRefused) {
  EXPECT_THROW(EncodeSdoValue("r32", "1e39"), SdoValueError);
  EXPECT_THROW(EncodeSdoValue("r64", "1e309"), SdoValueError);
  EXPECT_EQ(EncodeSdoValue("r32", "3.4e38").size(), 4u);
  EXPECT_EQ(FormatSdoValue("r32", EncodeSdoValue("r32", "inf")), "inf");
  EXPECT_EQ(FormatSdoValue("r64", EncodeSdoValue("r64", "-inf")), "-inf");
  EXPECT_EQ(FormatSdoValue("r32", EncodeSdoValue("r32", "nan")), "nan");
}

TEST(SdoValue, SurroundingSpacesAreIgnoredExceptInVisibleStrings) {
  EXPECT_EQ(EncodeSdoValue("u8", " 7 "), Bytes{7});
  EXPECT_EQ(EncodeSdoValue("vs", " a "), (Bytes{' ', 'a', ' '}));
}

TEST(SdoValue, UnknownTypesAreRefusedWithTheListOfTypes) {
  try {
    EncodeSdoValue("u7", "1");
    ADD_FAILURE() << "accepted";
  } catch (const SdoValueError& e) {
    EXPECT_STREQ(e.what(),
                 "unknown SDO type \"u7\" (expected one of b i8 i16 i32 i64 u8 u16 u32 u64 r32 r64 vs os d)");
  }
  EXPECT_THROW(FormatSdoValue("U8", Bytes{1}), SdoValueError) << "names are lower case, as cocomm's";
  EXPECT_THROW(RequireSdoType("x8"), SdoValueError);
  EXPECT_EQ(RequireSdoType("r64"), SdoType::kReal64);
  EXPECT_EQ(RequireSdoType(""), SdoType::kHex);
}

TEST(SdoValue, UploadedBytesThatDoNotFitTheTypeAreAnError) {
  try {
    FormatSdoValue("u32", Bytes{0x01});
    ADD_FAILURE() << "accepted";
  } catch (const SdoValueError& e) {
    EXPECT_STREQ(e.what(), "u32 is 4 bytes, got 1 (01)");
  }
  EXPECT_THROW(FormatSdoValue("u8", Bytes{}), SdoValueError);
  EXPECT_THROW(FormatSdoValue("b", Bytes{0x02}), SdoValueError) << "a boolean is 00 or 01";
}

TEST(SdoValue, VisibleStringsDropTrailingNulsAndEscapeControlBytes) {
  EXPECT_EQ(FormatSdoValue("vs", Bytes{'a', 'b', 0, 0}), "ab");
  EXPECT_EQ(FormatSdoValue("vs", Bytes{'a', '\n', 'b'}), "a\\x0Ab");
}

TEST(SdoValue, TypeNamesAndSizes) {
  for (const char* name :
       {"b", "i8", "i16", "i32", "i64", "u8", "u16", "u32", "u64", "r32", "r64", "vs", "os", "d"}) {
    const auto type = ParseSdoType(name);
    ASSERT_TRUE(type.has_value()) << name;
    EXPECT_EQ(SdoTypeName(*type), name);
  }
  EXPECT_EQ(SdoTypeSize(SdoType::kUnsigned16), 2u);
  EXPECT_EQ(SdoTypeSize(SdoType::kReal64), 8u);
  EXPECT_EQ(SdoTypeSize(SdoType::kVisibleString), 0u);
  EXPECT_FALSE(ParseSdoType("u128").has_value());
}

}  // namespace
}  // namespace canfleet::control
