// The INI layer of CiA 306 v1.3 §4.1 (basic structure): [sections], key=value lines, ';' comment
// lines, and what the lexer refuses.
#include "node/canopen/eds/ini_lexer.hpp"

#include <gtest/gtest.h>

#include "node/canopen/eds/eds_error.hpp"
#include "tests/unit/eds/eds_test_util.hpp"

namespace canfleet::canopen {
namespace {

TEST(IniLexerTest, SplitsSectionsAndEntriesWithTheirLineNumbers) {
  auto sections = LexIni("[FileInfo]\nFileName=a.eds\n\n[1000]\nParameterName=Device type\n", "a.eds");
  ASSERT_EQ(sections.size(), 2u);
  EXPECT_EQ(sections[0].name, "FileInfo");
  EXPECT_EQ(sections[0].line, 1u);
  ASSERT_EQ(sections[0].entries.size(), 1u);
  EXPECT_EQ(sections[0].entries[0].key, "FileName");
  EXPECT_EQ(sections[0].entries[0].value, "a.eds");
  EXPECT_EQ(sections[0].entries[0].line, 2u);
  EXPECT_EQ(sections[1].name, "1000");
  EXPECT_EQ(sections[1].line, 4u);
  EXPECT_EQ(sections[1].entries[0].line, 5u);
}

// CiA 306 §4.1: ';' starts a comment line. Files come from Windows tools: CRLF and a BOM.
TEST(IniLexerTest, SkipsCommentsBlankLinesBomAndCarriageReturns) {
  auto sections = LexIni(
      "\xEF\xBB\xBF; comment\r\n\r\n  [A]  \r\n# also a comment\r\n  k = v  \r\n   ; indented\r\n", "a.eds");
  ASSERT_EQ(sections.size(), 1u);
  EXPECT_EQ(sections[0].name, "A");
  EXPECT_EQ(sections[0].line, 3u);
  ASSERT_EQ(sections[0].entries.size(), 1u);
  EXPECT_EQ(sections[0].entries[0].key, "k");
  EXPECT_EQ(sections[0].entries[0].value, "v");  // trailing blanks trimmed
  EXPECT_EQ(sections[0].entries[0].line, 5u);
}

TEST(IniLexerTest, KeepsEqualsSignsAndSemicolonsInsideValues) {
  auto sections = LexIni("[A]\nk=a=b;c\nempty=\n[B] ; trailing comment\n", "a.eds");
  ASSERT_EQ(sections.size(), 2u);
  EXPECT_EQ(sections[0].entries[0].value, "a=b;c");
  EXPECT_EQ(sections[0].entries[1].value, "");
  EXPECT_EQ(sections[1].name, "B");
}

// A CRLF file converted to CRLF once more ends its lines in CR CR LF; a CR inside a line is not
// text (it could not be written back).
TEST(IniLexerTest, CarriageReturnsOnlyEndLines) {
  auto sections = LexIni("[A]\r\r\nk=v\tw\r\r\n", "a.eds");
  EXPECT_EQ(sections[0].entries[0].value, "v\tw");
  test::ExpectEdsError("[A]\nk=a\rb\n", {2, "", "", "carriage return inside a line"});
}

TEST(IniLexerTest, LastLineWithoutNewlineIsRead) {
  auto sections = LexIni("[A]\nk=v", "a.eds");
  ASSERT_EQ(sections[0].entries.size(), 1u);
  EXPECT_EQ(sections[0].entries[0].value, "v");
}

TEST(IniLexerTest, RejectsBinaryData) {
  using test::ExpectEdsError;
  constexpr char kNul[] = "[A]\nk=v\nx\0y=1\n";
  ExpectEdsError(std::string_view(kNul, sizeof kNul - 1), {3, "", "", "binary data (byte 0x00)"});
  ExpectEdsError("[A]\n\x7F\x45LF\n", {2, "", "", "binary data (byte 0x7F)"});
}

TEST(IniLexerTest, RejectsLinesThatAreNeitherSectionNorKeyValue) {
  using test::ExpectEdsError;
  ExpectEdsError("[A]\nk=v\njust text\n", {3, "", "", "expected [section] or key=value"});
  ExpectEdsError("[A\nk=v\n", {1, "", "", "without ']'"});
  ExpectEdsError("[A] x\n", {1, "", "", "unexpected text after section header"});
  ExpectEdsError("[ ]\n", {1, "", "", "empty section name"});
  ExpectEdsError("[A]\n=v\n", {2, "", "", "empty key"});
  ExpectEdsError("\nk=v\n[A]\n", {2, "", "", "before the first [section]"});
}

}  // namespace
}  // namespace canfleet::canopen
