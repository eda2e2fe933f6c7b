#include "bus/wire/message_writer.hpp"

#include <cstring>
#include <utility>

#include "bus/wire/varint.hpp"

namespace canfleet::wire {

namespace {

// Protobuf tags (field number << 3 | wire type 2 = length-delimited).
constexpr std::uint8_t kTagEnvelopeFrames = (3 << 3) | 2;
constexpr std::uint8_t kTagEnvelopeTxConfirm = (4 << 3) | 2;
constexpr std::uint8_t kTagBatchRecords = (1 << 3) | 2;

/// Header of a batch at its largest: three varints of at most 3 bytes (a batch is < 2^21 bytes)
/// and two tags.
constexpr std::size_t kMaxBatchRecordsBytes = kMaxFramesPerMessage * kFrameRecordSize;
constexpr std::size_t kMaxBatchHeader = 3 + 1 + 3 + 1 + 3;
static_assert(VarintSize(kMaxBatchRecordsBytes + 16) <= 3);

}  // namespace

void MessageWriter::OpenBatch(MessageType kind) {
  batch_open_ = true;
  batch_kind_ = kind;
  batch_start_ = buffer_.size();
  batch_frames_ = 0;
  buffer_.Extend(kMaxBatchHeader);
}

void MessageWriter::CloseBatch() {
  if (!batch_open_) return;
  batch_open_ = false;
  const std::size_t records = batch_frames_ * kFrameRecordSize;
  if (records == 0) {
    buffer_.Shrink(batch_start_);
    return;
  }
  // Envelope { frames|tx_confirm: FrameBatch { records: <records> } }, length-prefixed.
  const std::size_t inner = 1 + VarintSize(records) + records;
  const std::size_t envelope = 1 + VarintSize(inner) + inner;
  std::uint8_t header[kMaxBatchHeader];
  std::uint8_t* p = WriteVarint(envelope, header);
  *p++ = batch_kind_ == MessageType::kTxConfirm ? kTagEnvelopeTxConfirm : kTagEnvelopeFrames;
  p = WriteVarint(inner, p);
  *p++ = kTagBatchRecords;
  p = WriteVarint(records, p);
  const auto header_size = static_cast<std::size_t>(p - header);
  std::uint8_t* start = buffer_.data() + batch_start_;
  if (header_size < kMaxBatchHeader) {
    std::memmove(start + header_size, start + kMaxBatchHeader, records);
    buffer_.Shrink(buffer_.size() - (kMaxBatchHeader - header_size));
  }
  std::memcpy(start, header, header_size);
}

template <class Fill>
void MessageWriter::AppendProto(Fill&& fill) {
  CloseBatch();
  Envelope envelope;
  fill(envelope);
  const std::size_t size = envelope.ByteSizeLong();
  std::uint8_t* body = WriteVarint(size, buffer_.Extend(VarintSize(size) + size));
  envelope.SerializeWithCachedSizesToArray(body);
}

void MessageWriter::AddHello(const Hello& hello) {
  AppendProto([&](Envelope& e) { *e.mutable_hello() = hello; });
}

void MessageWriter::AddHelloReply(const HelloReply& reply) {
  AppendProto([&](Envelope& e) { *e.mutable_hello_reply() = reply; });
}

void MessageWriter::AddControllerEvent(const canfleet::ControllerEvent& event) {
  AppendProto([&](Envelope& e) {
    ControllerEvent& out = *e.mutable_controller_event();
    out.set_state(ToWire(event.state));
    out.set_tec(event.tec);
    out.set_rec(event.rec);
  });
}

void MessageWriter::AddPing(std::uint64_t nonce) {
  AppendProto([&](Envelope& e) { e.mutable_ping()->set_nonce(nonce); });
}

void MessageWriter::AddPong(std::uint64_t nonce) {
  AppendProto([&](Envelope& e) { e.mutable_pong()->set_nonce(nonce); });
}

void MessageWriter::AddError(std::string_view reason) {
  AppendProto([&](Envelope& e) { e.mutable_error()->set_reason(std::string(reason)); });
}

void MessageWriter::AddNodeRequest(const NodeRequest& request) {
  AppendProto([&](Envelope& e) { *e.mutable_node_request() = request; });
}

void MessageWriter::AddNodeReply(const NodeReply& reply) {
  AppendProto([&](Envelope& e) { *e.mutable_node_reply() = reply; });
}

void MessageWriter::Clear() {
  buffer_.clear();
  batch_open_ = false;
  batch_frames_ = 0;
  frames_ = 0;
}

void MessageWriter::Swap(MessageWriter& other) noexcept {
  buffer_.swap(other.buffer_);
  std::swap(batch_open_, other.batch_open_);
  std::swap(batch_kind_, other.batch_kind_);
  std::swap(batch_start_, other.batch_start_);
  std::swap(batch_frames_, other.batch_frames_);
  std::swap(frames_, other.frames_);
}

}  // namespace canfleet::wire
