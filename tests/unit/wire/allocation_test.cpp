// The frame path allocates nothing per frame (issue 4: "frames batched (no per-frame allocation
// or syscall on the hot path)"): once the buffers have grown, encoding and decoding a steady
// stream of batches allocates nothing at all.
#include <gtest/gtest.h>

#include "tests/support/allocation_counter.hpp"
#include "tests/unit/wire/wire_test_support.hpp"

namespace canfleet::wire {
namespace {

TEST(WireAllocation, SteadyBatchesAllocateNothing) {
  MessageWriter filling;
  MessageWriter writing;
  StreamDecoder decoder;
  Message message;
  std::size_t decoded = 0;
  auto round = [&](std::size_t frames) {
    for (std::size_t i = 0; i < frames; ++i)
      filling.AddFrame(CanFrame::Data(0x180 + (i % 64), {1, 2, 3, 4, 5, 6, 7, 8}),
                       BusTime(static_cast<std::int64_t>(i)));
    filling.AddTxConfirm(CanFrame::Data(0x200, {1}), BusTime(1));
    filling.AddFrame(CanFrame::Data(0x201, {2}), BusTime(2));
    filling.Swap(writing);  // what a connection does when it starts a write
    const auto bytes = writing.Bytes();
    // Split the "socket read" in two so the decoder also handles a partial message.
    const std::size_t half = bytes.size() / 2;
    for (auto part : {bytes.subspan(0, half), bytes.subspan(half)}) {
      auto space = decoder.WritableSpace(part.size());
      std::copy(part.begin(), part.end(), space.begin());
      decoder.Commit(part.size());
      while (decoder.Next(message) == StreamDecoder::Result::kMessage)
        decoded += message.frames.size();
    }
    writing.Clear();
  };
  for (int i = 0; i < 3; ++i)
    round(5000);  // warm-up: buffers grow to their working size
  const auto before = canfleet::test::AllocationCount();
  decoded = 0;
  for (int i = 0; i < 100; ++i)
    round(5000);
  EXPECT_EQ(canfleet::test::AllocationCount() - before, 0u);
  EXPECT_EQ(decoded, 100u * 5002u);
  EXPECT_FALSE(decoder.Failed()) << decoder.Error();
}

TEST(WireAllocation, SteadyPreEncodedBatchesAllocateNothing) {
  // The broker's delivery path: one encoding of the round, copied by every session.
  std::vector<std::uint8_t> records(500 * kFrameRecordSize);
  for (std::size_t i = 0; i < 500; ++i)
    EncodeRecord(CanFrame::Data(0x180 + (i % 64), {1, 2, 3, 4, 5, 6, 7, 8}),
                 BusTime(static_cast<std::int64_t>(i)), records.data() + i * kFrameRecordSize);
  MessageWriter filling;
  MessageWriter writing;
  std::size_t bytes = 0;
  auto round = [&] {
    for (int session = 0; session < 4; ++session) {
      filling.AddRecords(MessageType::kFrames, records.data(), 100);
      filling.AddRecords(MessageType::kFrames, records.data() + 101 * kFrameRecordSize, 399);
      filling.AddTxConfirm(CanFrame::Data(0x200, {1}), BusTime(1));
    }
    filling.Swap(writing);
    bytes += writing.Bytes().size();
    writing.Clear();
  };
  for (int i = 0; i < 3; ++i)
    round();
  const auto before = canfleet::test::AllocationCount();
  for (int i = 0; i < 100; ++i)
    round();
  EXPECT_EQ(canfleet::test::AllocationCount() - before, 0u);
  EXPECT_GT(bytes, 100u * 4u * 499u * kFrameRecordSize);
}

}  // namespace
}  // namespace canfleet::wire
