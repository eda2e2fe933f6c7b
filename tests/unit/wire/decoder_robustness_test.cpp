// Nothing a peer sends may crash, hang or wedge a service (CONTRIBUTING.md); malformed, oversized
// or garbage input is a protocol error that names its reason (issue 4, "Node <-> broker protocol").
#include <gtest/gtest.h>

#include <random>

#include "bus/wire/message_writer.hpp"
#include "tests/unit/wire/wire_test_support.hpp"

namespace canfleet::wire {
namespace {

using namespace test;

Bytes Prefixed(const Bytes& body) {
  Bytes out;
  std::uint64_t n = body.size();
  while (n >= 0x80) {
    out.push_back(static_cast<std::uint8_t>(n | 0x80));
    n >>= 7;
  }
  out.push_back(static_cast<std::uint8_t>(n));
  out.insert(out.end(), body.begin(), body.end());
  return out;
}

/// Envelope { frames: FrameBatch { records: <records> } } with the given raw records.
Bytes BatchWithRecords(const Bytes& records) {
  Bytes inner = {0x0A};
  inner.push_back(static_cast<std::uint8_t>(records.size()));
  inner.insert(inner.end(), records.begin(), records.end());
  Bytes body = {0x1A, static_cast<std::uint8_t>(inner.size())};
  body.insert(body.end(), inner.begin(), inner.end());
  return Prefixed(body);
}

Bytes ValidRecord() {
  std::uint8_t record[kFrameRecordSize];
  EncodeRecord(CanFrame::Data(0x123, {1, 2, 3}), BusTime(10), record);
  return Bytes(record, record + sizeof record);
}

TEST(WireDecoder, OversizedMessageIsRefusedFromItsPrefix) {
  // 2 MiB announced: refused as soon as the prefix is read, without buffering the body.
  const Bytes prefix = {0x80, 0x80, 0x80, 0x01};  // 2^21
  const DecodeOutcome out = DecodeAll(prefix);
  EXPECT_TRUE(out.failed);
  EXPECT_EQ(out.error, "message of 2097152 bytes exceeds the limit of 1048576");
}

TEST(WireDecoder, MessageAtTheLimitIsAccepted) {
  Envelope e;
  e.mutable_error()->set_reason(std::string(kMaxMessageSize - 8, 'x'));
  std::string body = e.SerializeAsString();
  ASSERT_LE(body.size(), kMaxMessageSize);
  const DecodeOutcome out = DecodeAll(Prefixed(ToBytes(body)), 4096);
  EXPECT_FALSE(out.failed) << out.error;
  ASSERT_EQ(out.messages.size(), 1u);
}

TEST(WireDecoder, OverlongLengthPrefixIsAnError) {
  const DecodeOutcome out = DecodeAll(Bytes(11, 0xFF));
  EXPECT_TRUE(out.failed);
  EXPECT_EQ(out.error, "malformed length prefix");
}

TEST(WireDecoder, EmptyMessageIsAnError) {
  const DecodeOutcome out = DecodeAll(Bytes{0x00});
  EXPECT_TRUE(out.failed);
  EXPECT_EQ(out.error, "empty message");
}

TEST(WireDecoder, RecordsNotAMultipleOf24AreAnError) {
  Bytes records = ValidRecord();
  records.pop_back();
  const DecodeOutcome out = DecodeAll(BatchWithRecords(records));
  EXPECT_TRUE(out.failed);
  EXPECT_EQ(out.error, "malformed message: frame records of 23 bytes: not a multiple of 24");
}

TEST(WireDecoder, InvalidRecordsAreAnError) {
  struct Case {
    std::size_t offset;
    std::uint8_t value;
    const char* error;
  };
  const Case cases[] = {
      {12, 9, "malformed message: frame record 1: DLC 9 above 8"},
      {13, 0x08, "malformed message: frame record 1: unknown flag bits 8"},
      {9, 0x08, "malformed message: frame record 1: identifier 2083 too large for its format"},
      {14, 1, "malformed message: frame record 1: reserved bytes not zero"},
  };
  for (const Case& c : cases) {
    Bytes bad = ValidRecord();
    bad[c.offset] = c.value;
    Bytes records = ValidRecord();
    records.insert(records.end(), bad.begin(), bad.end());
    const DecodeOutcome out = DecodeAll(BatchWithRecords(records));
    EXPECT_TRUE(out.failed);
    EXPECT_EQ(out.error, c.error);
    EXPECT_TRUE(out.messages.empty()) << "a batch is taken whole or not at all";
  }
}

TEST(WireDecoder, ExtendedIdentifiersUpTo29Bits) {
  Bytes record = ValidRecord();
  record[8] = 0xFF;
  record[9] = 0xFF;
  record[10] = 0xFF;
  record[11] = 0x1F;
  record[13] = CanFrame::kExtended;
  EXPECT_FALSE(DecodeAll(BatchWithRecords(record)).failed);
  record[11] = 0x20;
  EXPECT_TRUE(DecodeAll(BatchWithRecords(record)).failed);
}

TEST(WireDecoder, NotAnEnvelopeIsAnError) {
  const DecodeOutcome out = DecodeAll(Prefixed({0xFF, 0xFF, 0xFF}));
  EXPECT_TRUE(out.failed);
  EXPECT_EQ(out.error, "malformed message: not a canfleet.wire.Envelope");
}

TEST(WireDecoder, UnknownBodyIsAnError) {
  // Field 15 (varint 1): valid protobuf, but no body this protocol version knows.
  const DecodeOutcome out = DecodeAll(Prefixed({0x78, 0x01}));
  EXPECT_TRUE(out.failed);
  EXPECT_EQ(out.error, "malformed message: Envelope without a known body");
}

TEST(WireDecoder, ControllerEventOutOfRangeIsAnError) {
  Envelope e;
  e.mutable_controller_event()->set_state(static_cast<ControllerState>(7));
  DecodeOutcome out = DecodeAll(Prefixed(ToBytes(e.SerializeAsString())));
  EXPECT_TRUE(out.failed);
  EXPECT_EQ(out.error, "malformed message: unknown controller state 7");

  e.mutable_controller_event()->set_state(CONTROLLER_STATE_BUS_OFF);
  e.mutable_controller_event()->set_rec(256);
  out = DecodeAll(Prefixed(ToBytes(e.SerializeAsString())));
  EXPECT_TRUE(out.failed);
  EXPECT_EQ(out.error, "malformed message: error counters out of range (TEC 0, REC 256)");
}

TEST(WireDecoder, TruncatedFieldsInsideABatchAreErrors) {
  // The outer length is right, the FrameBatch inside lies about its field lengths.
  for (const Bytes& inner :
       {Bytes{0x0A, 0x30, 0x01}, Bytes{0x0A}, Bytes{0x0B}, Bytes{0x00}, Bytes{0x09, 0x01}}) {
    Bytes body = {0x1A, static_cast<std::uint8_t>(inner.size())};
    body.insert(body.end(), inner.begin(), inner.end());
    const DecodeOutcome out = DecodeAll(Prefixed(body));
    EXPECT_TRUE(out.failed) << "inner " << int(inner[0]);
    EXPECT_TRUE(out.error.starts_with("malformed message:")) << out.error;
  }
}

TEST(WireDecoder, FailedDecoderStaysFailed) {
  StreamDecoder decoder;
  Message m;
  decoder.Feed(Bytes{0x00});
  EXPECT_EQ(decoder.Next(m), StreamDecoder::Result::kError);
  MessageWriter w;
  w.AddPing(1);
  decoder.Feed(w.Bytes());
  EXPECT_EQ(decoder.Next(m), StreamDecoder::Result::kError);
  EXPECT_EQ(decoder.Error(), "empty message");
}

TEST(WireDecoder, GarbageNeverCrashesAndNeverYieldsInvalidFrames) {
  // Random bytes, random splits: every outcome is "need more", "message" or "error", and every
  // frame handed out is valid.
  std::mt19937 rng(1234);
  for (int round = 0; round < 2000; ++round) {
    const std::size_t n = std::uniform_int_distribution<std::size_t>(1, 300)(rng);
    Bytes garbage(n);
    for (auto& b : garbage)
      b = static_cast<std::uint8_t>(rng());
    if (round % 3 == 0) {
      // Often start with a plausible prefix and tag so the body parsers are reached.
      garbage[0] = static_cast<std::uint8_t>(std::min<std::size_t>(n - 1, 127));
      if (n > 1) garbage[1] = round % 2 ? 0x1A : 0x0A;
    }
    StreamDecoder decoder;
    Message m;
    std::size_t at = 0;
    while (at < n) {
      const std::size_t chunk =
          std::min<std::size_t>(std::uniform_int_distribution<std::size_t>(1, 64)(rng), n - at);
      decoder.Feed(std::span(garbage).subspan(at, chunk));
      at += chunk;
      StreamDecoder::Result r;
      while ((r = decoder.Next(m)) == StreamDecoder::Result::kMessage) {
        for (std::size_t i = 0; i < m.frames.size(); ++i)
          ASSERT_TRUE(m.frames[i].frame.valid());
      }
      if (r == StreamDecoder::Result::kError) {
        ASSERT_FALSE(decoder.Error().empty());
        break;
      }
    }
  }
}

TEST(WireDecoder, BufferStaysBoundedByOneMessage) {
  // A peer announcing a 1 MiB message and trickling it in costs at most one message of memory.
  StreamDecoder decoder;
  const Bytes prefix = {0x80, 0x80, 0x40};  // exactly 1 MiB
  decoder.Feed(prefix);
  Message m;
  EXPECT_EQ(decoder.Next(m), StreamDecoder::Result::kNeedMore);
  auto space = decoder.WritableSpace(16);
  EXPECT_GE(space.size(), kMaxMessageSize);
  EXPECT_LE(space.size(), kMaxMessageSize + 64 * 1024);
}

}  // namespace
}  // namespace canfleet::wire

namespace canfleet::wire {
namespace {

using namespace test;

// Virtual time (protocol 4): a grant that does not move time forward, or a reply whose next
// deadline is not after the time reached, would stall or rewind a fleet's clock: refused.
TEST(WireDecoder, ATimeGrantThatDoesNotMoveTimeForwardIsAnError) {
  MessageWriter w;
  w.AddTimeGrant(5000, 5000);
  const DecodeOutcome out = DecodeAll(w.Bytes());
  EXPECT_TRUE(out.failed);
  EXPECT_EQ(out.error, "malformed message: TimeGrant until_ns 5000 not after now_ns 5000 (or negative)");
}

TEST(WireDecoder, ATimeReachedWhoseNextDeadlineIsNotLaterIsAnError) {
  MessageWriter w;
  w.AddTimeReached(5000, 4000);
  const DecodeOutcome out = DecodeAll(w.Bytes());
  EXPECT_TRUE(out.failed);
  EXPECT_EQ(out.error,
            "malformed message: TimeReached next_deadline_ns 4000 not after time_ns 5000 (or negative)");
}

}  // namespace
}  // namespace canfleet::wire
