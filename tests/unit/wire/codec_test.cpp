// The node <-> broker codec (issue 4, "Node <-> broker protocol": protobuf schema,
// length-delimited, frames batched). Messages survive a round trip through MessageWriter and
// StreamDecoder whatever the read boundaries, and the hand-encoded batches are exactly what
// protobuf writes for the same Envelope.
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/util/delimited_message_util.h>
#include <gtest/gtest.h>

#include <random>

#include "tests/unit/wire/wire_test_support.hpp"

namespace canfleet::wire {
namespace {

using namespace test;

std::string Delimited(const Envelope& envelope) {
  std::string out;
  google::protobuf::io::StringOutputStream stream(&out);
  EXPECT_TRUE(google::protobuf::util::SerializeDelimitedToZeroCopyStream(envelope, &stream));
  return out;
}

/// A stream with one of everything, in an order that mixes batches and control messages.
Bytes MixedStream() {
  MessageWriter w;
  Hello hello = MakeHello("can0", "quad-5", 5);
  hello.set_tx_confirmations(true);
  hello.set_bitrate(125'000);
  w.AddHello(hello);
  HelloReply reply;
  reply.set_accepted(true);
  reply.set_protocol_version(kProtocolVersion);
  reply.set_bitrate(500'000);
  reply.set_mode(BUS_MODE_PACED);
  reply.set_port_id(3);
  w.AddHelloReply(reply);
  w.AddFrame(Frame("123#DEADBEEF"), BusTime(1000));
  w.AddFrame(Frame("7FF#"), BusTime(2000));
  w.AddFrame(Frame("1FFFFFFF#0102030405060708"), BusTime(3000));
  w.AddFrame(Frame("701#R1"), BusTime(4000));
  w.AddTxConfirm(Frame("185#01"), BusTime(4500));
  w.AddFrame(Frame("080#"), BusTime(5000));
  w.AddControllerEvent({canfleet::ControllerState::kErrorPassive, 128, 3});
  w.AddFrame(Frame("181#AA"), BusTime(6000));
  w.AddPing(42);
  w.AddPong(43);
  NodeRequest request;
  request.set_request_id(7);
  request.mutable_io_set()->set_name("IN1.voltage_mV");
  request.mutable_io_set()->set_value("3000");
  w.AddNodeRequest(request);
  NodeReply node_reply;
  node_reply.set_request_id(7);
  IoValue& value = *node_reply.add_values();
  value.set_name("IN1.voltage_mV");
  value.set_value("3000");
  value.set_unit("mV");
  value.set_input(true);
  w.AddNodeReply(node_reply);
  w.AddFrame(Frame("182#BB"), BusTime(7000));
  w.AddBitRate(250'000);
  w.AddTimeGrant(7000, 7024);
  w.AddTimeGrant(7024, 7048, std::vector<std::uint64_t>{3, 4});
  w.AddTimeReached(7024, 500'000'000);
  w.AddTimeReached(7024, std::nullopt);
  w.AddAcceptance(std::vector<std::uint32_t>{0x000, 0x605, 0x7E5});
  w.AddAcceptance(std::nullopt);
  w.AddError("bye");
  return ToBytes(w.Bytes());
}

const std::vector<std::string> kMixedExpected = {
    R"(Hello protocol_version: 4 bus: "can0" node_name: "quad-5" node_id: 5 role: ROLE_NODE tx_confirmations: true bitrate: 125000)",
    "HelloReply accepted: true protocol_version: 4 bitrate: 500000 mode: BUS_MODE_PACED port_id: 3",
    "FrameBatch 123#DEADBEEF@1000 7FF#@2000 1FFFFFFF#0102030405060708@3000 701#R1@4000",
    "TxConfirm 185#01@4500",
    "FrameBatch 080#@5000",
    "ControllerEvent error-passive 128 3",
    "FrameBatch 181#AA@6000",
    "Ping 42",
    "Pong 43",
    R"(NodeRequest request_id: 7 io_set { name: "IN1.voltage_mV" value: "3000" })",
    R"(NodeReply request_id: 7 values { name: "IN1.voltage_mV" value: "3000" unit: "mV" input: true })",
    "FrameBatch 182#BB@7000",
    "BitRate 250000",
    "TimeGrant 7000..7024",
    "TimeGrant 7024..7048 #3 #4",
    "TimeReached 7024 next 500000000",
    "TimeReached 7024 idle",
    "Acceptance 3 ids",
    "Acceptance all",
    "Error bye",
};

TEST(WireCodec, MixedStreamRoundTripsInOrder) {
  const DecodeOutcome out = DecodeAll(MixedStream());
  EXPECT_FALSE(out.failed) << out.error;
  EXPECT_EQ(out.messages, kMixedExpected);
}

TEST(WireCodec, ByteByByteGivesTheSameMessages) {
  // A read may end anywhere: inside the length prefix, a tag, a record.
  const DecodeOutcome out = DecodeAll(MixedStream(), 1);
  EXPECT_FALSE(out.failed) << out.error;
  EXPECT_EQ(out.messages, kMixedExpected);
}

TEST(WireCodec, RandomSplitsGiveTheSameMessages) {
  const Bytes stream = MixedStream();
  std::mt19937 rng(7);
  for (int round = 0; round < 200; ++round) {
    StreamDecoder decoder;
    Message m;
    std::vector<std::string> got;
    for (std::size_t at = 0; at < stream.size();) {
      const std::size_t n =
          std::min<std::size_t>(std::uniform_int_distribution<std::size_t>(1, 40)(rng), stream.size() - at);
      // Through WritableSpace/Commit, as a socket read does.
      auto space = decoder.WritableSpace(n);
      ASSERT_GE(space.size(), n);
      std::copy_n(stream.begin() + static_cast<std::ptrdiff_t>(at), n, space.begin());
      decoder.Commit(n);
      at += n;
      while (decoder.Next(m) == StreamDecoder::Result::kMessage)
        got.push_back(Describe(m));
      ASSERT_FALSE(decoder.Failed()) << decoder.Error();
    }
    ASSERT_EQ(got, kMixedExpected) << "round " << round;
  }
}

TEST(WireCodec, HandEncodedBatchIsWhatProtobufWrites) {
  // The hot path skips the generated code; any protobuf implementation must read it the same.
  MessageWriter w;
  Envelope expected;
  std::string records;
  for (std::uint32_t i = 0; i < 300; ++i) {  // 7200 bytes of records: two-byte varints
    const CanFrame f = CanFrame::Data(0x100 + (i % 0x600), {std::uint8_t(i), std::uint8_t(i >> 8)});
    w.AddFrame(f, BusTime(1'000'000 + i));
    std::uint8_t record[kFrameRecordSize];
    EncodeRecord(f, BusTime(1'000'000 + i), record);
    records.append(reinterpret_cast<const char*>(record), sizeof record);
  }
  expected.mutable_frames()->set_records(records);
  EXPECT_EQ(ToBytes(w.Bytes()), ToBytes(Delimited(expected)));

  MessageWriter one;
  one.AddTxConfirm(Frame("123#01"), BusTime(5));
  Envelope confirm;
  std::uint8_t record[kFrameRecordSize];
  EncodeRecord(Frame("123#01"), BusTime(5), record);
  confirm.mutable_tx_confirm()->set_records(
      std::string(reinterpret_cast<const char*>(record), sizeof record));
  EXPECT_EQ(ToBytes(one.Bytes()), ToBytes(Delimited(confirm)));
}

TEST(WireCodec, ProtobufEncodedMessagesDecode) {
  // Not the canonical form: an Envelope written field by field by protobuf, a FrameBatch with an
  // unknown field, an Envelope whose oneof is set twice (the last one wins).
  std::uint8_t record[kFrameRecordSize];
  EncodeRecord(Frame("321#0A0B"), BusTime(77), record);
  const std::string rec(reinterpret_cast<const char*>(record), sizeof record);

  Envelope batch;
  batch.mutable_frames()->set_records(rec + rec);
  std::string stream = Delimited(batch);

  // FrameBatch { records = rec; 5: varint 1 } inside Envelope field 3.
  std::string inner;
  inner += '\x0A';
  inner += static_cast<char>(rec.size());
  inner += rec;
  inner += "\x28\x01";
  std::string body;
  body += '\x1A';
  body += static_cast<char>(inner.size());
  body += inner;
  stream += static_cast<char>(body.size());
  stream += body;

  // Envelope { ping: {nonce 9}, frames: {records = rec} }: frames wins.
  std::string twice;
  twice += "\x32\x02\x08\x09";  // field 6 (ping), nonce 9
  twice += '\x1A';
  twice += static_cast<char>(rec.size() + 2);
  twice += '\x0A';
  twice += static_cast<char>(rec.size());
  twice += rec;
  stream += static_cast<char>(twice.size());
  stream += twice;

  const DecodeOutcome out = DecodeAll(ToBytes(stream));
  EXPECT_FALSE(out.failed) << out.error;
  EXPECT_EQ(out.messages, (std::vector<std::string>{"FrameBatch 321#0A0B@77 321#0A0B@77",
                                                    "FrameBatch 321#0A0B@77", "FrameBatch 321#0A0B@77"}));
}

TEST(WireCodec, LargeBatchesSplitIntoMessagesBelowTheLimit) {
  MessageWriter w;
  const std::size_t n = 2 * kMaxFramesPerMessage + 100;
  for (std::size_t i = 0; i < n; ++i)
    w.AddFrame(CanFrame::Data(0x200, {std::uint8_t(i), std::uint8_t(i >> 8), std::uint8_t(i >> 16)}),
               BusTime(static_cast<std::int64_t>(i)));
  EXPECT_EQ(w.frame_count(), n);
  const Bytes stream = ToBytes(w.Bytes());
  StreamDecoder decoder;
  decoder.Feed(stream);
  Message m;
  std::vector<std::size_t> sizes;
  std::size_t next = 0;
  while (decoder.Next(m) == StreamDecoder::Result::kMessage) {
    ASSERT_EQ(m.type, MessageType::kFrames);
    sizes.push_back(m.frames.size());
    for (std::size_t i = 0; i < m.frames.size(); ++i, ++next) {
      const StampedFrame f = m.frames[i];
      ASSERT_EQ(f.time.count(), static_cast<std::int64_t>(next));
      ASSERT_EQ(f.frame.data[0] | f.frame.data[1] << 8 | f.frame.data[2] << 16, static_cast<int>(next));
    }
  }
  EXPECT_FALSE(decoder.Failed()) << decoder.Error();
  EXPECT_EQ(sizes, (std::vector<std::size_t>{kMaxFramesPerMessage, kMaxFramesPerMessage, 100}));
}

TEST(WireCodec, BulkAppendWritesWhatSingleAppendsWrite) {
  // AddFrames (the broker's delivery path) and AddFrame (the node's Send path) must agree, also
  // across a batch split and after a message of another kind.
  std::vector<StampedFrame> frames;
  for (std::uint32_t i = 0; i < kMaxFramesPerMessage + 10; ++i)
    frames.push_back({CanFrame::Data(0x100 + (i % 0x80), {std::uint8_t(i), 7}), BusTime(i)});
  MessageWriter one_by_one;
  MessageWriter bulk;
  one_by_one.AddPing(1);
  bulk.AddPing(1);
  for (const auto& f : frames)
    one_by_one.AddTxConfirm(f.frame, f.time);
  const auto same = [](const StampedFrame& f) { return f; };
  bulk.AddFrames(MessageType::kTxConfirm, std::span<const StampedFrame>(frames).first(100), same);
  bulk.AddFrames(MessageType::kTxConfirm, std::span<const StampedFrame>(frames).subspan(100), same);
  bulk.AddFrames(MessageType::kFrames, std::span<const StampedFrame>(), same);  // nothing, no batch
  EXPECT_EQ(bulk.frame_count(), frames.size());
  EXPECT_EQ(ToBytes(bulk.Bytes()), ToBytes(one_by_one.Bytes()));
}

TEST(WireCodec, PreEncodedRecordsWriteWhatAddFramesWrites) {
  // AddRecords (the broker's shared round, encoded once for every session) and AddFrames must
  // agree, in several pieces, across a batch split and after a message of another kind.
  std::vector<StampedFrame> frames;
  for (std::uint32_t i = 0; i < kMaxFramesPerMessage + 10; ++i)
    frames.push_back({CanFrame::Data(0x100 + (i % 0x80), {std::uint8_t(i), 7}), BusTime(i)});
  std::vector<std::uint8_t> records(frames.size() * kFrameRecordSize);
  for (std::size_t i = 0; i < frames.size(); ++i)
    EncodeRecord(frames[i].frame, frames[i].time, records.data() + i * kFrameRecordSize);
  MessageWriter encoded;
  MessageWriter copied;
  encoded.AddPing(1);
  copied.AddPing(1);
  const auto same = [](const StampedFrame& f) { return f; };
  encoded.AddFrames(MessageType::kFrames, std::span<const StampedFrame>(frames), same);
  copied.AddRecords(MessageType::kFrames, records.data(), 3);
  copied.AddRecords(MessageType::kFrames, records.data() + 3 * kFrameRecordSize, frames.size() - 3);
  copied.AddRecords(MessageType::kFrames, records.data(), 0);  // nothing
  EXPECT_EQ(copied.frame_count(), frames.size());
  EXPECT_EQ(ToBytes(copied.Bytes()), ToBytes(encoded.Bytes()));

  // ExpectFrames only sizes the header: announcing fewer or more frames than follow gives the
  // same bytes (the header grows or shrinks when the batch is closed).
  for (std::size_t announced :
       {std::size_t{0}, std::size_t{1}, std::size_t{5}, std::size_t{6}, frames.size()}) {
    for (std::size_t count :
         {std::size_t{1}, std::size_t{5}, std::size_t{6}, std::size_t{600}, frames.size()}) {
      SCOPED_TRACE(std::to_string(announced) + " announced, " + std::to_string(count) + " written");
      MessageWriter expected;
      MessageWriter announcing;
      expected.AddFrames(MessageType::kFrames, std::span<const StampedFrame>(frames).first(count), same);
      announcing.ExpectFrames(MessageType::kFrames, announced);
      announcing.AddRecords(MessageType::kFrames, records.data(), count);
      EXPECT_EQ(ToBytes(announcing.Bytes()), ToBytes(expected.Bytes()));
    }
  }
}

TEST(WireCodec, RecordKeepsOnlyTheBytesOfTheFrame) {
  // Bytes beyond the DLC (and all of a remote frame's) travel as 0 (canfleet_wire.proto, FrameBatch).
  CanFrame f = CanFrame::Data(0x123, {1, 2});
  f.data[5] = 0xEE;
  std::uint8_t record[kFrameRecordSize];
  EncodeRecord(f, BusTime(-1), record);
  const Bytes expected = {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF,  // time -1
                          0x23, 0x01, 0x00, 0x00,                          // id
                          0x02, 0x00, 0x00, 0x00,                          // dlc, flags, reserved
                          0x01, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
  EXPECT_EQ(Bytes(record, record + sizeof record), expected);
  CanFrame r = CanFrame::Remote(0x701, 1);
  r.data[0] = 9;
  EncodeRecord(r, BusTime(0), record);
  EXPECT_EQ(record[13], CanFrame::kRemote);
  EXPECT_EQ(record[16], 0);
}

TEST(WireCodec, EmptyBatchWritesNothing) {
  MessageWriter w;
  w.AddPing(1);
  w.CloseBatch();
  const std::size_t before = w.Bytes().size();
  w.Clear();
  EXPECT_TRUE(w.empty());
  w.AddPing(1);
  EXPECT_EQ(w.Bytes().size(), before);
}

TEST(WireCodec, SwapExchangesWholeStreams) {
  MessageWriter a;
  MessageWriter b;
  a.AddFrame(Frame("123#01"));
  b.AddPing(5);
  a.Swap(b);
  EXPECT_EQ(DecodeAll(a.Bytes()).messages, std::vector<std::string>{"Ping 5"});
  EXPECT_EQ(DecodeAll(b.Bytes()).messages, std::vector<std::string>{"FrameBatch 123#01@0"});
}

}  // namespace
}  // namespace canfleet::wire
