// Value spellings of CiA 306 v1.3 §4.2 (entry value interpretation) and §4.6.3.2 (DefaultValue,
// LowLimit, HighLimit): hex/octal/decimal integers in their type's range, "$NODEID" formulas,
// reals, VISIBLE_STRING as text and OCTET_STRING/DOMAIN as hex; and the writer's spelling.
#include "node/canopen/eds/eds_value.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "node/canopen/eds/eds_number.hpp"

namespace canfleet::canopen {
namespace {

Bytes Parse(DataType type, std::string_view text) {
  auto value = ParseEdsValue(type, text, true);
  EXPECT_FALSE(value.adds_node_id) << text;
  return value.bytes;
}

std::string ErrorOf(DataType type, std::string_view text, bool allow_node_id = true) {
  try {
    ParseEdsValue(type, text, allow_node_id);
  } catch (const EdsValueError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(EdsNumberTest, ReadsHexOctalDecimalAndSigns) {
  EXPECT_EQ(ParseIntegerLiteral("0x1F")->magnitude, 0x1Fu);
  EXPECT_TRUE(ParseIntegerLiteral("0X1f")->hex);
  EXPECT_EQ(ParseIntegerLiteral("017")->magnitude, 15u);  // leading 0: octal, as in C
  EXPECT_EQ(ParseIntegerLiteral("0")->magnitude, 0u);
  EXPECT_EQ(ParseIntegerLiteral("42")->magnitude, 42u);
  EXPECT_TRUE(ParseIntegerLiteral("-42")->negative);
  EXPECT_FALSE(ParseIntegerLiteral("+42")->negative);
  EXPECT_EQ(ParseIntegerLiteral("18446744073709551615")->magnitude, 18446744073709551615u);
}

TEST(EdsNumberTest, RejectsWhatIsNotAnInteger) {
  for (std::string_view text :
       {"", "0x", "0xZZ", "08", "1.5", "12 3", "--1", "+", "18446744073709551616", "0x1h"}) {
    EXPECT_FALSE(ParseIntegerLiteral(text)) << text;
  }
}

TEST(EdsNumberTest, InlineCommentsAfterNumbersAreCut) {
  EXPECT_EQ(StripInlineComment("1000   ; ms"), "1000");
  EXPECT_EQ(StripInlineComment("0x10;x"), "0x10");
  EXPECT_EQ(StripInlineComment("  5  "), "5");
}

TEST(EdsValueTest, UnsignedValuesMustFitTheirType) {
  EXPECT_EQ(Parse(DataType::kUnsigned8, "255"), (Bytes{0xFF}));
  EXPECT_EQ(Parse(DataType::kUnsigned16, "0x1234"), (Bytes{0x34, 0x12}));
  EXPECT_EQ(Parse(DataType::kUnsigned24, "0xABCDEF"), (Bytes{0xEF, 0xCD, 0xAB}));
  EXPECT_EQ(Parse(DataType::kUnsigned64, "0xFFFFFFFFFFFFFFFF"), Bytes(8, 0xFF));
  EXPECT_EQ(Parse(DataType::kUnsigned8, "-0"), (Bytes{0}));
  EXPECT_EQ(ErrorOf(DataType::kUnsigned8, "300"), "\"300\" is out of range for UNSIGNED8 (0..255)");
  EXPECT_EQ(ErrorOf(DataType::kUnsigned8, "-1"), "\"-1\" is out of range for UNSIGNED8 (0..255)");
  EXPECT_EQ(ErrorOf(DataType::kUnsigned16, "0x10000"),
            "\"0x10000\" is out of range for UNSIGNED16 (0..65535)");
  EXPECT_EQ(ErrorOf(DataType::kUnsigned32, "0xZZ"), "\"0xZZ\" is not a number");
}

TEST(EdsValueTest, BooleanIsZeroOrOne) {
  EXPECT_EQ(Parse(DataType::kBoolean, "1"), (Bytes{1}));
  EXPECT_NE(ErrorOf(DataType::kBoolean, "2").find("out of range for BOOLEAN (0..1)"), std::string::npos);
}

// Signed limits are often written as two's complement hex (0x8300 = -32000 for INTEGER16).
TEST(EdsValueTest, SignedValuesTakeNegativeDecimalAndTwosComplementHex) {
  EXPECT_EQ(Parse(DataType::kInteger8, "-128"), (Bytes{0x80}));
  EXPECT_EQ(Parse(DataType::kInteger8, "127"), (Bytes{0x7F}));
  EXPECT_EQ(Parse(DataType::kInteger8, "0xFF"), (Bytes{0xFF}));
  EXPECT_EQ(Parse(DataType::kInteger16, "0x8300"), EncodeLe<std::int16_t>(-32000));
  EXPECT_EQ(Parse(DataType::kInteger16, "-0x10"), EncodeLe<std::int16_t>(-16));
  EXPECT_EQ(Parse(DataType::kInteger64, "-9223372036854775808"),
            EncodeLe(std::numeric_limits<std::int64_t>::min()));
  EXPECT_EQ(Parse(DataType::kInteger64, "0xFFFFFFFFFFFFFFFF"), EncodeLe<std::int64_t>(-1));
  EXPECT_EQ(Parse(DataType::kInteger24, "-1"), (Bytes{0xFF, 0xFF, 0xFF}));
  EXPECT_EQ(ErrorOf(DataType::kInteger8, "128"), "\"128\" is out of range for INTEGER8 (-128..127)");
  EXPECT_EQ(ErrorOf(DataType::kInteger8, "-129"), "\"-129\" is out of range for INTEGER8 (-128..127)");
  EXPECT_NE(ErrorOf(DataType::kInteger8, "0x100").find("out of range"), std::string::npos);
}

// CiA 306 v1.3 §4.6.3.2: "$NODEID+0x180" means the node-ID is added to 0x180 when applied.
TEST(EdsValueTest, NodeIdFormulasKeepTheConstantPart) {
  for (std::string_view text : {"$NODEID+0x180", "0x180+$NODEID", " $nodeid + 0x180 ", "$NodeId+384"}) {
    auto value = ParseEdsValue(DataType::kUnsigned32, text, true);
    EXPECT_TRUE(value.adds_node_id) << text;
    EXPECT_EQ(value.bytes, EncodeLe<std::uint32_t>(0x180)) << text;
  }
  auto alone = ParseEdsValue(DataType::kUnsigned8, "$NODEID", true);
  EXPECT_TRUE(alone.adds_node_id);
  EXPECT_EQ(alone.bytes, (Bytes{0}));
}

TEST(EdsValueTest, MalformedNodeIdFormulasAreErrors) {
  EXPECT_NE(ErrorOf(DataType::kUnsigned32, "$NODEID*2").find("not a number or a $NODEID+x formula"),
            std::string::npos);
  EXPECT_NE(ErrorOf(DataType::kUnsigned32, "$NODEID+").find("missing the number"), std::string::npos);
  EXPECT_NE(ErrorOf(DataType::kUnsigned32, "1+$NODEID+2").find("formula"), std::string::npos);
  EXPECT_NE(ErrorOf(DataType::kUnsigned32, "$NODEID+0xZZ").find("\"0xZZ\" is not a number"),
            std::string::npos);
  EXPECT_NE(ErrorOf(DataType::kUnsigned8, "$NODEID+0x100").find("out of range"), std::string::npos);
  EXPECT_NE(ErrorOf(DataType::kUnsigned32, "$NODEID+1", false).find("not allowed"), std::string::npos);
  EXPECT_NE(ErrorOf(DataType::kBoolean, "$NODEID").find("integer type"), std::string::npos);
  EXPECT_NE(ErrorOf(DataType::kReal32, "$NODEID+1").find("not a number"), std::string::npos);
}

TEST(EdsValueTest, RealsReadDecimalScientificAndHex) {
  EXPECT_EQ(Parse(DataType::kReal32, "0.125"), EncodeLe(0.125f));
  EXPECT_EQ(Parse(DataType::kReal32, "-1.5e3"), EncodeLe(-1500.0f));
  EXPECT_EQ(Parse(DataType::kReal32, "+2"), EncodeLe(2.0f));
  EXPECT_EQ(Parse(DataType::kReal32, "0x10"), EncodeLe(16.0f));
  EXPECT_EQ(Parse(DataType::kReal64, "0.1"), EncodeLe(0.1));
  EXPECT_EQ(Parse(DataType::kReal64, "-inf"), EncodeLe(-std::numeric_limits<double>::infinity()));
  EXPECT_EQ(Parse(DataType::kReal32, "nan"), EncodeLe(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_EQ(Parse(DataType::kReal32, "-nan"), EncodeLe(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_NE(ErrorOf(DataType::kReal32, "1e50").find("out of range"), std::string::npos);
  EXPECT_EQ(ErrorOf(DataType::kReal32, "1.5x"), "\"1.5x\" is not a number");
  EXPECT_EQ(ErrorOf(DataType::kReal64, "--1"), "\"--1\" is not a number");
}

TEST(EdsValueTest, StringsAreTextAndOctetStringsAreHex) {
  EXPECT_EQ(Parse(DataType::kVisibleString, "IO-401; rev B"), ToBytes("IO-401; rev B"));
  EXPECT_EQ(Parse(DataType::kOctetString, "01 02 A0 ff"), (Bytes{0x01, 0x02, 0xA0, 0xFF}));
  EXPECT_EQ(Parse(DataType::kDomain, "0xCAFE"), (Bytes{0xCA, 0xFE}));
  EXPECT_EQ(Parse(DataType::kDomain, ""), Bytes{});
  EXPECT_NE(ErrorOf(DataType::kOctetString, "123").find("odd number of digits"), std::string::npos);
  EXPECT_NE(ErrorOf(DataType::kDomain, "firmware.bin").find("not hex bytes"), std::string::npos);
}

TEST(EdsValueTest, WriterSpellsValuesSoTheyReadBack) {
  EXPECT_EQ(FormatEdsValue(DataType::kUnsigned32, EncodeLe<std::uint32_t>(0x180), false), "0x00000180");
  EXPECT_EQ(FormatEdsValue(DataType::kUnsigned32, EncodeLe<std::uint32_t>(0x180), true),
            "$NODEID+0x00000180");
  EXPECT_EQ(FormatEdsValue(DataType::kUnsigned8, Bytes{0}, true), "$NODEID");
  EXPECT_EQ(FormatEdsValue(DataType::kInteger16, EncodeLe<std::int16_t>(-5), false), "-5");
  EXPECT_EQ(FormatEdsValue(DataType::kBoolean, Bytes{1}, false), "1");
  EXPECT_EQ(FormatEdsValue(DataType::kReal64, EncodeLe(0.1), false), "0.1");
  EXPECT_EQ(FormatEdsValue(DataType::kReal32, EncodeLe(0.1f), false), "0.1");
  EXPECT_EQ(FormatEdsValue(DataType::kVisibleString, ToBytes("a;b"), false), "a;b");
  EXPECT_EQ(FormatEdsValue(DataType::kOctetString, Bytes{0x01, 0xAB}, false), "01AB");
  // Every REAL32 bit pattern but NaN payloads reads back to the same bits.
  for (float f : {1e-45f, 3.4028235e38f, -0.0f, 1.1754943e-38f, 0.3f}) {
    auto bytes = EncodeLe(f);
    EXPECT_EQ(Parse(DataType::kReal32, FormatEdsValue(DataType::kReal32, bytes, false)), bytes) << f;
  }
}

TEST(EdsValueTest, WritableTextHasNoLineBreaksOrOuterBlanks) {
  EXPECT_TRUE(IsWritableText("IO-401; rev B"));
  EXPECT_TRUE(IsWritableText(""));
  EXPECT_TRUE(IsWritableText("a\tb"));  // the lexer keeps tabs inside values
  EXPECT_FALSE(IsWritableText("a\nb"));
  EXPECT_FALSE(IsWritableText("a\rb"));
  EXPECT_FALSE(IsWritableText(" a"));
  EXPECT_FALSE(IsWritableText("a\t"));
}

}  // namespace
}  // namespace canfleet::canopen
