#include "bus/wire/message_writer.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

#include "bus/wire/varint.hpp"

namespace canfleet::wire {

namespace {

// Protobuf tags (field number << 3 | wire type 2 = length-delimited).
constexpr std::uint8_t kTagEnvelopeFrames = (3 << 3) | 2;
constexpr std::uint8_t kTagEnvelopeTxConfirm = (4 << 3) | 2;
constexpr std::uint8_t kTagBatchRecords = (1 << 3) | 2;

/// Header of a batch at its largest (wire::kMaxBatchHeader): three varints of at most 3 bytes
/// (a batch is < 2^21 bytes) and two tags.
constexpr std::size_t kMaxBatchRecordsBytes = kMaxFramesPerMessage * kFrameRecordSize;
static_assert(VarintSize(kMaxBatchRecordsBytes + 16) <= 3);
static_assert(3 + 1 + 3 + 1 + 3 <= kMaxBatchHeader);

/// The header of a batch of `records` bytes: Envelope length, tag, FrameBatch length, tag,
/// records length.
constexpr std::size_t BatchHeaderSize(std::size_t records) {
  const std::size_t inner = 1 + VarintSize(records) + records;
  const std::size_t envelope = 1 + VarintSize(inner) + inner;
  return VarintSize(envelope) + envelope - records;
}
static_assert(BatchHeaderSize(kMaxBatchRecordsBytes) <= kMaxBatchHeader);

}  // namespace

void MessageWriter::OpenBatch(MessageType kind, std::size_t expected) {
  batch_open_ = true;
  batch_kind_ = kind;
  batch_start_ = buffer_.size();
  batch_frames_ = 0;
  batch_header_ =
      BatchHeaderSize(std::min(std::max<std::size_t>(expected, 1), kMaxFramesPerMessage) * kFrameRecordSize);
  buffer_.Extend(batch_header_);
}

void MessageWriter::CloseBatch() {
  if (!batch_open_) return;
  batch_open_ = false;
  const std::size_t records = batch_frames_ * kFrameRecordSize;
  if (records == 0) {
    buffer_.Shrink(batch_start_);
    return;
  }
  std::uint8_t header[kMaxBatchHeader];
  const std::size_t header_size = WriteBatchHeader(batch_kind_, batch_frames_, header);
  if (header_size < batch_header_) {
    std::uint8_t* start = buffer_.data() + batch_start_;
    std::memmove(start + header_size, start + batch_header_, records);
    buffer_.Shrink(buffer_.size() - (batch_header_ - header_size));
  } else if (header_size > batch_header_) {
    buffer_.Extend(header_size - batch_header_);  // may move the buffer: take `start` after
    std::uint8_t* start = buffer_.data() + batch_start_;
    std::memmove(start + header_size, start + batch_header_, records);
  }
  std::memcpy(buffer_.data() + batch_start_, header, header_size);
}

std::size_t WriteBatchHeader(MessageType kind, std::size_t frames, std::uint8_t* out) {
  // Envelope { frames|tx_confirm: FrameBatch { records: <records> } }, length-prefixed.
  const std::size_t records = frames * kFrameRecordSize;
  const std::size_t inner = 1 + VarintSize(records) + records;
  const std::size_t envelope = 1 + VarintSize(inner) + inner;
  std::uint8_t* p = WriteVarint(envelope, out);
  *p++ = kind == MessageType::kTxConfirm ? kTagEnvelopeTxConfirm : kTagEnvelopeFrames;
  p = WriteVarint(inner, p);
  *p++ = kTagBatchRecords;
  p = WriteVarint(records, p);
  return static_cast<std::size_t>(p - out);
}

void MessageWriter::AddEncoded(const std::uint8_t* bytes, std::size_t size) {
  CloseBatch();
  if (size != 0) std::memcpy(buffer_.Extend(size), bytes, size);
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

void MessageWriter::AddBitRate(std::uint32_t bitrate) {
  AppendProto([&](Envelope& e) { e.mutable_bit_rate()->set_bitrate(bitrate); });
}

void MessageWriter::AddTimeGrant(std::int64_t now_ns, std::int64_t until_ns,
                                 std::span<const std::uint64_t> attachments) {
  AppendProto([&](Envelope& e) {
    auto* grant = e.mutable_time_grant();
    grant->set_now_ns(now_ns);
    grant->set_until_ns(until_ns);
    grant->mutable_attachments()->Add(attachments.begin(), attachments.end());
  });
}

void MessageWriter::AddTimeReached(std::int64_t time_ns, std::optional<std::int64_t> next_deadline_ns,
                                   const ReachedOutlook* outlook) {
  AppendProto([&](Envelope& e) {
    auto* reached = e.mutable_time_reached();
    reached->set_time_ns(time_ns);
    reached->set_has_deadline(next_deadline_ns.has_value());
    reached->set_next_deadline_ns(next_deadline_ns.value_or(0));
    if (outlook == nullptr) return;
    reached->set_has_outlook(true);
    reached->set_has_any(outlook->any_ns.has_value());
    reached->set_any_ns(outlook->any_ns.value_or(0));
    for (const auto& confined : outlook->confined) {
      auto* c = reached->add_confined();
      c->set_id(confined.id);
      c->set_deadline_ns(confined.deadline_ns);
      c->set_heartbeat(confined.heartbeat);
    }
  });
}

void MessageWriter::AddAcceptance(const std::optional<std::vector<std::uint32_t>>& ids,
                                  std::span<const std::pair<std::uint32_t, std::int64_t>> passive) {
  AppendProto([&](Envelope& e) {
    auto* acceptance = e.mutable_acceptance();
    acceptance->set_all(!ids.has_value());
    if (ids) acceptance->mutable_ids()->Add(ids->begin(), ids->end());
    for (const auto& [id, delay] : passive) {
      auto* p = acceptance->add_passive();
      p->set_id(id);
      p->set_delay_ns(delay);
    }
  });
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
  std::swap(batch_header_, other.batch_header_);
  std::swap(batch_frames_, other.batch_frames_);
  std::swap(frames_, other.frames_);
}

}  // namespace canfleet::wire
