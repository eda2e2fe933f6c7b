#include "bus/wire/stream_decoder.hpp"

#include <algorithm>
#include <cstring>

#include "bus/wire/varint.hpp"

namespace canfleet::wire {

namespace {

// Protobuf wire types (encoding.md): 0 varint, 1 64-bit, 2 length-delimited, 5 32-bit.
constexpr std::uint64_t kWireVarint = 0;
constexpr std::uint64_t kWireFixed64 = 1;
constexpr std::uint64_t kWireLength = 2;
constexpr std::uint64_t kWireFixed32 = 5;

constexpr std::uint64_t kTagEnvelopeFrames = (3 << 3) | kWireLength;
constexpr std::uint64_t kTagEnvelopeTxConfirm = (4 << 3) | kWireLength;

}  // namespace

StreamDecoder::StreamDecoder(std::size_t max_message) : max_message_(max_message) {}

std::span<std::uint8_t> StreamDecoder::WritableSpace(std::size_t min) {
  const std::size_t buffered = end_ - begin_;
  const std::size_t want = std::max(min, wanted_ > buffered ? wanted_ - buffered : std::size_t{0});
  if (buffer_.size() - end_ < want) {
    if (begin_ > 0) {
      std::memmove(buffer_.data(), buffer_.data() + begin_, buffered);
      begin_ = 0;
      end_ = buffered;
    }
    // Uninitialised growth: the socket writes what it reads, and untouched pages cost no memory.
    if (buffer_.size() - end_ < want) buffer_.Extend(end_ + want - buffer_.size());
  }
  return {buffer_.data() + end_, buffer_.size() - end_};
}

void StreamDecoder::Commit(std::size_t n) {
  end_ = std::min(end_ + n, buffer_.size());
}

void StreamDecoder::Feed(std::span<const std::uint8_t> bytes) {
  if (bytes.empty()) return;
  std::span<std::uint8_t> space = WritableSpace(bytes.size());
  std::memcpy(space.data(), bytes.data(), bytes.size());
  Commit(bytes.size());
}

StreamDecoder::Result StreamDecoder::Fail(std::string reason) {
  failed_ = true;
  error_ = std::move(reason);
  return Result::kError;
}

StreamDecoder::Result StreamDecoder::Next(Message& out) {
  if (failed_) return Result::kError;
  const std::span<const std::uint8_t> available(buffer_.data() + begin_, end_ - begin_);
  if (available.empty()) {
    begin_ = end_ = 0;  // nothing pending: the next read starts at the front, no memmove needed
    return Result::kNeedMore;
  }
  std::uint64_t size = 0;
  std::size_t prefix = 0;
  switch (ReadVarint(available, size, prefix)) {
    case VarintStatus::kIncomplete:
      return Result::kNeedMore;
    case VarintStatus::kOverlong:
      return Fail("malformed length prefix");
    case VarintStatus::kOk:
      break;
  }
  if (size > max_message_)
    return Fail("message of " + std::to_string(size) + " bytes exceeds the limit of " +
                std::to_string(max_message_));
  if (size == 0) return Fail("empty message");
  const std::size_t total = prefix + static_cast<std::size_t>(size);
  if (available.size() < total) {
    wanted_ = total;
    return Result::kNeedMore;
  }
  wanted_ = 0;
  begin_ += total;
  if (!DecodeBody(available.subspan(prefix, static_cast<std::size_t>(size)), out))
    return Fail("malformed message: " + error_);
  return Result::kMessage;
}

bool StreamDecoder::DecodeBody(std::span<const std::uint8_t> body, Message& out) {
  // Fast path: the whole body is one frames/tx_confirm field (the canonical encoding).
  std::uint64_t tag = 0;
  std::size_t tag_size = 0;
  if (ReadVarint(body, tag, tag_size) == VarintStatus::kOk &&
      (tag == kTagEnvelopeFrames || tag == kTagEnvelopeTxConfirm)) {
    std::uint64_t length = 0;
    std::size_t length_size = 0;
    const auto rest = body.subspan(tag_size);
    if (ReadVarint(rest, length, length_size) == VarintStatus::kOk && length == rest.size() - length_size) {
      const MessageType type = tag == kTagEnvelopeFrames ? MessageType::kFrames : MessageType::kTxConfirm;
      return DecodeBatchFast(rest.subspan(length_size), type, out);
    }
  }
  return DecodeEnvelope(body, out);
}

bool StreamDecoder::DecodeBatchFast(std::span<const std::uint8_t> batch, MessageType type, Message& out) {
  // FrameBatch { bytes records = 1; }: the last records field wins (protobuf semantics for a
  // singular field); unknown fields are skipped.
  std::span<const std::uint8_t> records;
  std::size_t pos = 0;
  while (pos < batch.size()) {
    std::uint64_t key = 0;
    std::size_t n = 0;
    if (ReadVarint(batch.subspan(pos), key, n) != VarintStatus::kOk) {
      error_ = "truncated field key in FrameBatch";
      return false;
    }
    pos += n;
    const std::uint64_t field = key >> 3;
    const std::uint64_t wire_type = key & 7;
    if (field == 0) {
      error_ = "field number 0 in FrameBatch";
      return false;
    }
    std::size_t skip = 0;
    switch (wire_type) {
      case kWireVarint: {
        std::uint64_t ignored = 0;
        if (ReadVarint(batch.subspan(pos), ignored, skip) != VarintStatus::kOk) {
          error_ = "truncated varint in FrameBatch";
          return false;
        }
        break;
      }
      case kWireFixed64:
        skip = 8;
        break;
      case kWireFixed32:
        skip = 4;
        break;
      case kWireLength: {
        std::uint64_t length = 0;
        if (ReadVarint(batch.subspan(pos), length, n) != VarintStatus::kOk ||
            length > batch.size() - pos - n) {
          error_ = "truncated length-delimited field in FrameBatch";
          return false;
        }
        pos += n;
        skip = static_cast<std::size_t>(length);
        if (field == 1) records = batch.subspan(pos, skip);
        break;
      }
      default:
        error_ = "unsupported wire type " + std::to_string(wire_type) + " in FrameBatch";
        return false;
    }
    if (skip > batch.size() - pos) {
      error_ = "truncated field in FrameBatch";
      return false;
    }
    pos += skip;
  }
  if (!ValidateRecords(records, error_)) return false;
  out.type = type;
  out.frames = FrameRecords(records);
  return true;
}

bool StreamDecoder::DecodeEnvelope(std::span<const std::uint8_t> body, Message& out) {
  Envelope& envelope = out.envelope;
  if (!envelope.ParseFromArray(body.data(), static_cast<int>(body.size()))) {
    error_ = "not a canfleet.wire.Envelope";
    return false;
  }
  switch (envelope.body_case()) {
    case Envelope::kHello:
      out.type = MessageType::kHello;
      return true;
    case Envelope::kHelloReply:
      out.type = MessageType::kHelloReply;
      return true;
    case Envelope::kFrames:
    case Envelope::kTxConfirm: {
      const bool frames = envelope.body_case() == Envelope::kFrames;
      const std::string& bytes = frames ? envelope.frames().records() : envelope.tx_confirm().records();
      const std::span<const std::uint8_t> records(reinterpret_cast<const std::uint8_t*>(bytes.data()),
                                                  bytes.size());
      if (!ValidateRecords(records, error_)) return false;
      out.type = frames ? MessageType::kFrames : MessageType::kTxConfirm;
      out.frames = FrameRecords(records);
      return true;
    }
    case Envelope::kControllerEvent: {
      const ControllerEvent& event = envelope.controller_event();
      const auto state = FromWire(event.state());
      if (!state) {
        error_ = "unknown controller state " + std::to_string(event.state());
        return false;
      }
      if (event.tec() > 0xFFFF || event.rec() > 0xFF) {
        error_ = "error counters out of range (TEC " + std::to_string(event.tec()) + ", REC " +
                 std::to_string(event.rec()) + ")";
        return false;
      }
      out.type = MessageType::kControllerEvent;
      out.controller = {*state, static_cast<std::uint16_t>(event.tec()),
                        static_cast<std::uint8_t>(event.rec())};
      return true;
    }
    case Envelope::kPing:
      out.type = MessageType::kPing;
      return true;
    case Envelope::kPong:
      out.type = MessageType::kPong;
      return true;
    case Envelope::kError:
      out.type = MessageType::kError;
      return true;
    case Envelope::kNodeRequest:
      out.type = MessageType::kNodeRequest;
      return true;
    case Envelope::kNodeReply:
      out.type = MessageType::kNodeReply;
      return true;
    case Envelope::kBitRate:
      out.type = MessageType::kBitRate;
      return true;
    case Envelope::kTimeGrant: {
      const TimeGrant& grant = out.envelope.time_grant();
      if (grant.now_ns() < 0 || grant.until_ns() <= grant.now_ns()) {
        error_ = "TimeGrant until_ns " + std::to_string(grant.until_ns()) + " not after now_ns " +
                 std::to_string(grant.now_ns()) + " (or negative)";
        return false;
      }
      out.type = MessageType::kTimeGrant;
      return true;
    }
    case Envelope::kTimeReached: {
      const TimeReached& reached = out.envelope.time_reached();
      if (reached.time_ns() < 0 ||
          (reached.has_deadline() && reached.next_deadline_ns() <= reached.time_ns())) {
        error_ = "TimeReached next_deadline_ns " + std::to_string(reached.next_deadline_ns()) +
                 " not after time_ns " + std::to_string(reached.time_ns()) + " (or negative)";
        return false;
      }
      out.type = MessageType::kTimeReached;
      return true;
    }
    case Envelope::kAcceptance: {
      const Acceptance& acceptance = out.envelope.acceptance();
      if (acceptance.ids_size() > 2048) {
        error_ = "Acceptance with " + std::to_string(acceptance.ids_size()) + " identifiers (at most 2048)";
        return false;
      }
      for (const std::uint32_t id : acceptance.ids()) {
        if (id > 0x7FF) {
          error_ = "Acceptance identifier " + std::to_string(id) + " is not an 11-bit identifier";
          return false;
        }
      }
      out.type = MessageType::kAcceptance;
      return true;
    }
    case Envelope::BODY_NOT_SET:
      break;
  }
  error_ = "Envelope without a known body";
  return false;
}

}  // namespace canfleet::wire
