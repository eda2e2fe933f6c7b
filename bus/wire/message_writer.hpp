#pragma once
/// @file Encodes messages into one growing byte buffer, ready for a single write. The buffer is
/// reused from write to write, so a steady stream of frames costs no allocation.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include "bus/wire/byte_buffer.hpp"
#include "bus/wire/messages.hpp"

namespace canfleet::wire {

/// Bytes of the largest frames-batch header (WriteBatchHeader).
inline constexpr std::size_t kMaxBatchHeader = 11;

/// Writes at `out` (kMaxBatchHeader bytes of room) the start of a length-delimited Envelope that
/// holds one batch of `frames` records of `kind` (kFrames or kTxConfirm), byte-identical to what
/// MessageWriter writes; the `frames` records (EncodeRecord) follow it on the wire. Returns its
/// size. `frames` is 1..kMaxFramesPerMessage. Lets a writer send records it did not copy (the
/// broker's round encoding, shared by every session) behind a header of its own.
std::size_t WriteBatchHeader(MessageType kind, std::size_t frames, std::uint8_t* out);

/// Appends length-delimited Envelopes (canfleet_wire.proto) to a buffer.
///
/// Frames go into an open batch: consecutive frames of the same kind extend one FrameBatch message
/// (split every kMaxFramesPerMessage frames); any other message closes it first, so the stream
/// keeps the order of the calls. The batch's header is reserved at its maximum size and shrunk
/// when it is closed (one memmove of the batch), so frames are written once, in place.
///
/// Frames and TX confirmations are encoded by hand, byte-identical to what protobuf writes for the
/// same Envelope (tests check it both ways); the rare control messages go through the generated
/// code.
class MessageWriter {
 public:
  MessageWriter() = default;

  /// Appends one frame to the open frames batch (opening one if needed).
  void AddFrame(const CanFrame& frame, BusTime time = BusTime::zero()) {
    AddRecord(MessageType::kFrames, frame, time);
  }
  /// Appends one frame to the open TX-confirmation batch.
  void AddTxConfirm(const CanFrame& frame, BusTime time) { AddRecord(MessageType::kTxConfirm, frame, time); }

  /// Appends many frames at once (`kind`: kFrames or kTxConfirm): one size check per batch rather
  /// than per frame. `stamp(item)` gives each item's StampedFrame.
  template <class T, class Stamp>
  void AddFrames(MessageType kind, std::span<const T> items, Stamp&& stamp) {
    std::size_t done = 0;
    while (done < items.size()) {
      const std::size_t n = std::min(Room(kind, items.size() - done), items.size() - done);
      std::uint8_t* out = buffer_.Extend(n * kFrameRecordSize);
      for (std::size_t i = 0; i < n; ++i, out += kFrameRecordSize) {
        const StampedFrame s = stamp(items[done + i]);
        EncodeRecord(s.frame, s.time, out);
      }
      batch_frames_ += n;
      frames_ += n;
      done += n;
    }
  }

  /// Appends `count` records already encoded by EncodeRecord (kFrameRecordSize bytes each, e.g.
  /// one encoding of a broker round shared by every session): a copy, no encoding.
  void AddRecords(MessageType kind, const std::uint8_t* records, std::size_t count) {
    while (count != 0) {
      const std::size_t n = std::min(Room(kind, count), count);
      std::memcpy(buffer_.Extend(n * kFrameRecordSize), records, n * kFrameRecordSize);
      batch_frames_ += n;
      frames_ += n;
      records += n * kFrameRecordSize;
      count -= n;
    }
  }

  /// Announces that `count` frames of `kind` follow (e.g. the runs of one delivery): a batch
  /// opened now reserves a header of the right size, so closing it moves nothing. Optional.
  void ExpectFrames(MessageType kind, std::size_t count) { Room(kind, count); }

  void AddHello(const Hello& hello);
  void AddHelloReply(const HelloReply& reply);
  void AddControllerEvent(const canfleet::ControllerEvent& event);
  void AddPing(std::uint64_t nonce);
  void AddPong(std::uint64_t nonce);
  void AddError(std::string_view reason);
  void AddNodeRequest(const NodeRequest& request);
  void AddNodeReply(const NodeReply& reply);
  /// BitRate{bitrate}: the node's controller now runs at `bitrate` bit/s (0: the bus's rate).
  void AddBitRate(std::uint32_t bitrate);
  /// TimeGrant{now_ns, until_ns, attachments} (virtual time, broker -> node): `attachments` names
  /// the node process's connections the round grants (TimeGrant.attachments).
  void AddTimeGrant(std::int64_t now_ns, std::int64_t until_ns,
                    std::span<const std::uint64_t> attachments = {});
  /// What a node's timers may send (TimeReached's outlook, per-node lookahead), in nanoseconds.
  struct ReachedOutlook {
    struct Confined {
      std::uint32_t id;  ///< 11-bit
      std::int64_t deadline_ns;
      bool heartbeat;
    };
    std::optional<std::int64_t> any_ns;  ///< any identifier from then on
    std::vector<Confined> confined;
  };
  /// TimeReached{time_ns, next deadline, outlook} (virtual time, node -> broker); no deadline:
  /// nullopt; no outlook: nullptr (the broker takes every timer to send anything).
  void AddTimeReached(std::int64_t time_ns, std::optional<std::int64_t> next_deadline_ns,
                      const ReachedOutlook* outlook = nullptr);
  /// Acceptance{ids, passive} (node -> broker); nullopt: every frame. `passive`: (identifier,
  /// delay in ns) of heartbeats answered with nothing before that delay.
  void AddAcceptance(const std::optional<std::vector<std::uint32_t>>& ids,
                     std::span<const std::pair<std::uint32_t, std::int64_t>> passive = {});
  /// Appends bytes that are already wire encoding (messages, or the unwritten tail of a write
  /// that went to the socket only in part), after closing the open batch.
  void AddEncoded(const std::uint8_t* bytes, std::size_t size);

  /// Closes the open batch, if any.
  void CloseBatch();

  /// Every message appended so far (closes the open batch).
  std::span<const std::uint8_t> Bytes() {
    CloseBatch();
    return buffer_.bytes();
  }
  /// Bytes appended so far, counting an open batch at its reserved size.
  std::size_t size() const { return buffer_.size(); }
  bool empty() const { return buffer_.empty(); }
  /// Frames appended since the last Clear.
  std::size_t frame_count() const { return frames_; }

  /// Forgets every message; keeps the storage.
  void Clear();

  /// Exchanges contents with another writer (double buffering: fill one while the other is
  /// being written).
  void Swap(MessageWriter& other) noexcept;

 private:
  void AddRecord(MessageType kind, const CanFrame& frame, BusTime time) {
    Room(kind, kMaxFramesPerMessage);
    EncodeRecord(frame, time, buffer_.Extend(kFrameRecordSize));
    ++batch_frames_;
    ++frames_;
  }
  /// Makes sure a batch of `kind` is open and has room; returns how many frames it can still take.
  /// A batch opened here reserves the header for `expected` frames (it grows if more come).
  std::size_t Room(MessageType kind, std::size_t expected) {
    if (batch_open_ && batch_kind_ == kind && batch_frames_ < kMaxFramesPerMessage)
      return kMaxFramesPerMessage - batch_frames_;
    CloseBatch();
    OpenBatch(kind, expected);
    return kMaxFramesPerMessage;
  }
  void OpenBatch(MessageType kind, std::size_t expected);
  /// Appends a protobuf-encoded Envelope.
  template <class Fill>
  void AppendProto(Fill&& fill);

  ByteBuffer buffer_;
  // The open batch: its kind, where its reserved header starts, how many frames it holds.
  bool batch_open_ = false;
  MessageType batch_kind_ = MessageType::kFrames;
  std::size_t batch_start_ = 0;
  std::size_t batch_header_ = 0;  ///< bytes reserved for its header
  std::size_t batch_frames_ = 0;
  std::size_t frames_ = 0;
};

}  // namespace canfleet::wire
