// The socketcand protocol as linux-can/socketcand speaks it (doc/protocol.md; state_raw.c for the
// exact formats: "< frame %03X|%08X %lld.%06lld " + "%02X" per byte + " >"; receive_command for
// the element framing; "< send %x %hhu %hhx ... >" with 8 id digits meaning EFF).
#include "orchestrator/socketcand/protocol.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/support/bus_probe.hpp"

namespace canfleet::socketcand {
namespace {

using canfleet::test::Frame;

WallTime At(std::int64_t seconds, std::int64_t us = 0) {
  return WallTime(std::chrono::seconds(seconds) + std::chrono::microseconds(us));
}

std::vector<std::string> Elements(ElementReader& reader) {
  std::vector<std::string> out;
  for (;;) {
    const auto r = reader.Next();
    if (r.status != ElementReader::Status::kElement) break;
    out.emplace_back(r.element);
  }
  return out;
}

// ---- element framing

TEST(ElementReader, SplitsElementsAndDropsGarbageBetweenThem) {
  ElementReader r;
  r.Feed("< open can0 >< rawmode >\r\n junk < echo >");
  EXPECT_EQ(Elements(r), (std::vector<std::string>{"< open can0 >", "< rawmode >", "< echo >"}));
  EXPECT_EQ(r.DiscardedBytes(), 8u);
  EXPECT_EQ(r.Buffered(), 0u);
}

TEST(ElementReader, JoinsAnElementSplitAcrossReads) {
  ElementReader r;
  r.Feed("< send 12");
  EXPECT_EQ(r.Next().status, ElementReader::Status::kNeedMore);
  r.Feed("3 1 AA");
  EXPECT_EQ(r.Next().status, ElementReader::Status::kNeedMore);
  r.Feed(" >< ec");
  EXPECT_EQ(Elements(r), (std::vector<std::string>{"< send 123 1 AA >"}));
  r.Feed("ho >");
  EXPECT_EQ(Elements(r), (std::vector<std::string>{"< echo >"}));
}

TEST(ElementReader, AnUnterminatedElementIsDroppedWhenANewOneStarts) {
  ElementReader r;
  r.Feed("< send 123 < echo >");
  EXPECT_EQ(Elements(r), (std::vector<std::string>{"< echo >"}));
  EXPECT_EQ(r.DiscardedBytes(), 11u);
}

TEST(ElementReader, AStrayClosingBracketIsGarbage) {
  ElementReader r;
  r.Feed("> >< echo >");
  EXPECT_EQ(Elements(r), (std::vector<std::string>{"< echo >"}));
}

TEST(ElementReader, BoundsTheElementLength) {
  ElementReader r;
  r.Feed("<" + std::string(kMaxElementLength - 2, 'x'));
  EXPECT_EQ(r.Next().status, ElementReader::Status::kNeedMore);
  r.Feed(">");  // exactly kMaxElementLength bytes: accepted
  EXPECT_EQ(r.Next().status, ElementReader::Status::kElement);
  r.Feed("<" + std::string(kMaxElementLength, 'x'));
  EXPECT_EQ(r.Next().status, ElementReader::Status::kTooLong);
  ElementReader complete;
  complete.Feed("<" + std::string(kMaxElementLength, 'x') + ">");
  EXPECT_EQ(complete.Next().status, ElementReader::Status::kTooLong);
}

TEST(ElementReader, GarbageWithoutElementsIsNotKept) {
  ElementReader r;
  for (int i = 0; i < 1000; ++i)
    r.Feed(std::string(1000, '\x01'));
  EXPECT_EQ(r.Next().status, ElementReader::Status::kNeedMore);
  EXPECT_EQ(r.Buffered(), 0u);
  EXPECT_EQ(r.DiscardedBytes(), 1'000'000u);
}

// ---- commands

TEST(ParseCommand, ModesOpenAndEcho) {
  const Command open = ParseCommand("< open can0 >");
  EXPECT_EQ(open.kind, CommandKind::kOpen);
  EXPECT_EQ(open.argument, "can0");
  EXPECT_EQ(ParseCommand("< rawmode >").kind, CommandKind::kRawMode);
  EXPECT_EQ(ParseCommand("< bcmmode >").kind, CommandKind::kBcmMode);
  EXPECT_EQ(ParseCommand("< isotpmode >").kind, CommandKind::kIsotpMode);
  EXPECT_EQ(ParseCommand("< controlmode >").kind, CommandKind::kControlMode);
  EXPECT_EQ(ParseCommand("< echo >").kind, CommandKind::kEcho);
  EXPECT_EQ(ParseCommand("<echo>").kind, CommandKind::kEcho);
  EXPECT_EQ(ParseCommand("<\techo\t>").kind, CommandKind::kEcho);
}

TEST(ParseCommand, MalformedOpenNamesTheCommand) {
  for (const char* text : {"< open >", "< open a b >", "< open abcdefghijklmnopq >"}) {
    const Command c = ParseCommand(text);
    EXPECT_EQ(c.kind, CommandKind::kMalformed) << text;
    EXPECT_EQ(c.argument, "open") << text;
  }
  EXPECT_EQ(ParseCommand("< open abcdefghijklmnop >").kind, CommandKind::kOpen);  // 16 characters
}

TEST(ParseCommand, SendStandardFrame) {
  const Command c = ParseCommand("< send 123 4 DE AD BE EF >");
  ASSERT_EQ(c.kind, CommandKind::kSend);
  EXPECT_EQ(c.frame, Frame("123#DEADBEEF"));
}

TEST(ParseCommand, SendAsPythonCanWritesIt) {
  // python-can: f"< send {id:X} {dlc:X} {' '.join(f'{b:x}')} >": lower case, no leading zeros.
  const Command c = ParseCommand("< send 181 3 de ad 5 >");
  ASSERT_EQ(c.kind, CommandKind::kSend);
  EXPECT_EQ(c.frame, Frame("181#DEAD05"));
  const Command empty = ParseCommand("< send 80 0  >");
  ASSERT_EQ(empty.kind, CommandKind::kSend);
  EXPECT_EQ(empty.frame, Frame("080#"));
}

TEST(ParseCommand, EightIdDigitsMeanAnExtendedIdentifier) {
  const Command c = ParseCommand("< send 00000123 1 FF >");
  ASSERT_EQ(c.kind, CommandKind::kSend);
  EXPECT_EQ(c.frame, Frame("00000123#FF"));
  EXPECT_TRUE(c.frame.extended());
  EXPECT_EQ(ParseCommand("< send 1AAAAAAA 2 1 F1 >").frame, Frame("1AAAAAAA#01F1"));
  EXPECT_FALSE(ParseCommand("< send 7FF 0 >").frame.extended());
}

TEST(ParseCommand, ExtendedIdWithoutLeadingZerosIsNotTruncated) {
  // python-can 4.1.0 writes the 29-bit id 12345h as "12345".
  const Command c = ParseCommand("< send 12345 0 >");
  ASSERT_EQ(c.kind, CommandKind::kSend);
  EXPECT_TRUE(c.frame.extended());
  EXPECT_EQ(c.frame.id, 0x12345u);
}

TEST(ParseCommand, SendRtr) {
  const Command c = ParseCommand("< sendrtr 705 1 >");
  ASSERT_EQ(c.kind, CommandKind::kSendRtr);
  EXPECT_EQ(c.frame, CanFrame::Remote(0x705, 1));
  const Command ext = ParseCommand("< sendrtr 1AAAAAAA 2 >");
  ASSERT_EQ(ext.kind, CommandKind::kSendRtr);
  EXPECT_TRUE(ext.frame.extended());
  EXPECT_TRUE(ext.frame.remote());
}

TEST(ParseCommand, MalformedSendsAreRejectedWithAReason) {
  for (const char* text : {
           "< send >",                          // no id
           "< send 123 >",                      // no DLC
           "< send 123 9 1 2 3 4 5 6 7 8 9 >",  // DLC above 8
           "< send 123 2 1 >",                  // fewer bytes than the DLC
           "< send 123 1 1 2 >",                // more bytes than the DLC
           "< send 123 1 100 >",                // byte with 3 digits
           "< send 123 1 GG >",                 // not hex
           "< send 0x123 0 >",                  // sscanf would take it; we do not
           "< send 123456789 0 >",              // 9 id digits
           "< send 20000000 0 >",               // above 1FFFFFFF
           "< send -1 0 >",                     //
           "< send 123 -1 >",                   //
           "< send 123 08 >",                   // DLC with two digits
           "< sendrtr 705 1 00 >",              // a remote frame has no data
           "< send 123 2 1 2 3 4 5 6 7 8 9 10 11 12 13 >",
       }) {
    const Command c = ParseCommand(text);
    EXPECT_EQ(c.kind, CommandKind::kMalformed) << text;
    EXPECT_NE(std::string(c.error), "") << text;
    EXPECT_TRUE(c.argument == "send" || c.argument == "sendrtr") << text;
  }
}

TEST(ParseCommand, UnknownAndUnservedCommands) {
  EXPECT_EQ(ParseCommand("< subscribe 0 0 123 >").kind, CommandKind::kBcmCommand);
  EXPECT_EQ(ParseCommand("< add 1 0 123 8 11 22 33 44 55 66 77 88 >").kind, CommandKind::kBcmCommand);
  EXPECT_EQ(ParseCommand("< can0 B 500000 0 0 0 0 0 0 0 >").kind, CommandKind::kBusConfig);
  const Command unknown = ParseCommand("< fly away >");
  EXPECT_EQ(unknown.kind, CommandKind::kUnknown);
  EXPECT_EQ(unknown.argument, "fly");
  EXPECT_EQ(ParseCommand("< >").kind, CommandKind::kMalformed);
  EXPECT_EQ(ParseCommand("<>").kind, CommandKind::kMalformed);
  EXPECT_EQ(ParseCommand("send 1 0").kind, CommandKind::kMalformed);
  EXPECT_EQ(ParseCommand("").kind, CommandKind::kMalformed);
  EXPECT_EQ(ParseCommand("< rawmode now >").kind, CommandKind::kMalformed);
}

// ---- what the server writes

TEST(AppendFrame, DataFramesAsSocketcandPrintsThem) {
  std::string out;
  EXPECT_TRUE(AppendFrame(out, Frame("123#DEADBEEF"), At(1700000000, 123456), false));
  EXPECT_EQ(out, "< frame 123 1700000000.123456 DEADBEEF >");
  out.clear();
  AppendFrame(out, Frame("1ABCDEF0#0011223344556677"), At(1700000000, 5), false);
  EXPECT_EQ(out, "< frame 1ABCDEF0 1700000000.000005 0011223344556677 >");
  out.clear();
  CanFrame small_ext = Frame("123#01");
  small_ext.flags |= CanFrame::kExtended;
  AppendFrame(out, small_ext, At(1700000000), false);
  EXPECT_EQ(out, "< frame 00000123 1700000000.000000 01 >");
  out.clear();
  AppendFrame(out, Frame("080#"), At(1700000000), false);  // socketcand prints two spaces
  EXPECT_EQ(out, "< frame 080 1700000000.000000  >");
}

TEST(AppendFrame, TimeIsTruncatedToMicroseconds) {
  std::string out;
  AppendFrame(out, Frame("001#"), At(5, 999999) + std::chrono::nanoseconds(999), false);
  EXPECT_EQ(out, "< frame 001 5.999999  >");
}

TEST(AppendFrame, RemoteFramesAsDocumented) {
  std::string out;
  AppendFrame(out, CanFrame::Remote(0x705, 1), At(1700000000, 42), false);
  EXPECT_EQ(out, "< rtr 705 1700000000.000042 1 >");
}

TEST(AppendFrame, ErrorFramesAreNotForwarded) {
  CanFrame f;
  f.flags = CanFrame::kError;
  std::string out = "x";
  EXPECT_FALSE(AppendFrame(out, f, At(1700000000), false));
  EXPECT_EQ(out, "x");
}

TEST(AppendFrame, AlignedRecordsFillSixtyFourBytesAndEndWithTheMessage) {
  std::string out;
  AppendFrame(out, Frame("1FFFFFFF#0011223344556677"), At(1700000000, 1), true);
  AppendFrame(out, Frame("080#"), At(1700000000, 2), true);
  ASSERT_EQ(out.size(), 2 * kAlignedRecordSize);
  const std::string first = out.substr(0, 64);
  const std::string second = out.substr(64);
  EXPECT_EQ(first.substr(first.find('<')), "< frame 1FFFFFFF 1700000000.000001 0011223344556677 >");
  EXPECT_EQ(first.find_first_not_of(' '), first.find('<'));
  EXPECT_EQ(second.substr(second.find('<')), "< frame 080 1700000000.000002  >");
  // 1024 / 64 records: a 1024-byte read ends exactly at a record's '>'.
  EXPECT_EQ(1024 % kAlignedRecordSize, 0u);
  EXPECT_EQ(out[63], '>');
}

TEST(AppendMessage, PadsOnlyWhenAsked) {
  std::string out;
  AppendMessage(out, "< echo >", false);
  EXPECT_EQ(out, "< echo >");
  AppendMessage(out, "< echo >", true);
  EXPECT_EQ(out.size(), 8 + kAlignedRecordSize);
  EXPECT_EQ(out.substr(out.size() - 8), "< echo >");
}

TEST(FormatSend, RoundTripsThroughTheParser) {
  CanFrame small_ext = Frame("123#01");
  small_ext.flags |= CanFrame::kExtended;
  CanFrame ext_rtr = CanFrame::Remote(0x1ABCDEF0, 8);
  ext_rtr.flags |= CanFrame::kExtended;
  for (const CanFrame& f : {Frame("123#DEADBEEF"), Frame("000#"), Frame("1FFFFFFF#0011223344556677"),
                            small_ext, CanFrame::Remote(0x705, 0), ext_rtr}) {
    const std::string text = FormatSend(f);
    const Command c = ParseCommand(text);
    ASSERT_TRUE(c.kind == CommandKind::kSend || c.kind == CommandKind::kSendRtr) << text;
    EXPECT_EQ(c.frame, f) << text;
  }
  EXPECT_EQ(FormatSend(Frame("123#DEAD")), "< send 123 2 DE AD >");
  EXPECT_EQ(FormatSend(CanFrame::Remote(0x705, 1)), "< sendrtr 705 1 >");
}

}  // namespace
}  // namespace canfleet::socketcand
