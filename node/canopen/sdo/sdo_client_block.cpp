// SDO client, block download and block upload (CiA 301 v4.2 §7.2.4.3.8–15). The mirror image of
// block_download.cpp / block_upload.cpp of the server.
#include <algorithm>
#include <array>
#include <span>

#include "node/canopen/sdo/crc16_ccitt.hpp"
#include "node/canopen/sdo/sdo_client.hpp"

namespace canfleet::canopen {

// ---- block download ----------------------------------------------------------------------------

// Initiate block download response: 1010 0s00 | index | sub-index | blksize.
void SdoClient::OnBlockDownloadInitiateResponse(const sdo::Payload& response) {
  if (!MultiplexerMatches(response)) return Fail(SdoAbort::kParameterIncompatible);
  const std::uint8_t blksize = response[4];
  if (blksize == 0 || blksize > sdo::kMaxBlockSize) return Fail(SdoAbort::kInvalidBlockSize);
  transfer_.crc = options_.crc && (response[0] & sdo::kBlockCrc) != 0;  // CRC only if both support it
  transfer_.blksize = blksize;
  transfer_.offset = 0;
  SendSubBlock();
}

// Up to blksize segments `c << 7 | seqno, 7 bytes` from the first unconfirmed byte, sent without
// waiting (§7.2.4.3.10). The frames are built first so the state is final before any goes out.
void SdoClient::SendSubBlock() {
  const auto& data = transfer_.data;
  std::array<sdo::Payload, sdo::kMaxBlockSize> frames;
  std::size_t count = 0;
  std::size_t at = transfer_.offset;
  bool last = false;
  while (count < transfer_.blksize && !last) {
    const auto n = std::min(sdo::kSegmentBytes, data.size() - at);
    last = at + n >= data.size();
    frames[count] =
        sdo::BlockSegment(static_cast<std::uint8_t>(count + 1), last, std::span(data).subspan(at, n));
    ++count;
    at += n;
  }
  transfer_.seqno = static_cast<std::uint8_t>(count);
  transfer_.last = last;
  Await(State::kBlockDownloadSubBlock);
  const auto generation = ++generation_;
  for (std::size_t i = 0; i < count && generation == generation_; ++i)
    Send(frames[i]);
}

// Block download response: A2h | ackseq | blksize. Segments after ackseq are sent again in the next
// sub-block; when all are confirmed the end request carries n and the CRC.
void SdoClient::OnBlockDownloadAck(const sdo::Payload& response) {
  const std::uint8_t ackseq = response[1];
  const std::uint8_t blksize = response[2];
  if (ackseq > transfer_.seqno) return Fail(SdoAbort::kInvalidSequence);
  if (blksize == 0 || blksize > sdo::kMaxBlockSize) return Fail(SdoAbort::kInvalidBlockSize);
  const auto& data = transfer_.data;
  transfer_.offset = std::min(data.size(), transfer_.offset + std::size_t{ackseq} * sdo::kSegmentBytes);
  transfer_.blksize = blksize;
  if (ackseq == transfer_.seqno && transfer_.last) {
    const auto crc = transfer_.crc ? Crc16Ccitt(data) : std::uint16_t{0};
    Await(State::kBlockDownloadEnd);
    Send(sdo::BlockEnd(sdo::UnusedInLastSegment(data.size()), crc));
    return;
  }
  SendSubBlock();
}

// ---- block upload ------------------------------------------------------------------------------

// Initiate block upload response: 1100 0s s 0 | index | sub-index | size (if s). Start with A3h.
void SdoClient::OnBlockUploadInitiateResponse(const sdo::Payload& response) {
  if (!MultiplexerMatches(response)) return Fail(SdoAbort::kParameterIncompatible);
  const std::uint8_t cs = response[0];
  transfer_.crc = options_.crc && (cs & sdo::kBlockCrc) != 0;
  if (cs & sdo::kBlockSize) {
    const std::uint32_t size = sdo::U32At(response, 4);
    if (size > options_.max_upload_bytes) return Fail(SdoAbort::kOutOfMemory);
    transfer_.size = size;
    transfer_.data.reserve(std::size_t{size} + sdo::kSegmentBytes);
  }
  transfer_.seqno = 0;
  transfer_.blksize = options_.block_size;
  Await(State::kBlockUploadSubBlock);
  RestartSubBlockTimer();
  Send(sdo::BlockUploadStart());
}

// Upload sub-block segment: c << 7 | seqno, 7 bytes. Only the next one in sequence is kept; after
// seqno = blksize or c = 1 the client acknowledges the last one it kept.
void SdoClient::OnBlockUploadSegment(const sdo::Payload& response) {
  const std::uint8_t seqno = response[0] & sdo::kSeqnoMask;
  const bool last = (response[0] & sdo::kBlockLast) != 0;
  if (seqno == 0 || seqno > transfer_.blksize) return Fail(SdoAbort::kInvalidSequence);
  RestartTimeout();
  if (seqno == transfer_.seqno + 1) {
    auto& data = transfer_.data;
    data.insert(data.end(), response.begin() + 1, response.end());
    transfer_.seqno = seqno;
    transfer_.last = last;
    if (transfer_.size && data.size() > std::size_t{*transfer_.size} + sdo::kSegmentBytes) {
      return Fail(SdoAbort::kTypeMismatch);
    }
    if (data.size() > options_.max_upload_bytes + sdo::kSegmentBytes) return Fail(SdoAbort::kOutOfMemory);
  }
  if (seqno == transfer_.blksize || last) return AcknowledgeSubBlock();
  RestartSubBlockTimer();
}

// Block upload response: A2h | ackseq | blksize. Does not restart the SDO timeout: only the
// server's frames do, so a silent server still times out although the stall timer acknowledges.
void SdoClient::AcknowledgeSubBlock() {
  const std::uint8_t ackseq = transfer_.seqno;
  transfer_.seqno = 0;
  if (transfer_.last) {
    sub_block_timer_.Cancel();
    transfer_.state = State::kBlockUploadEnd;
  } else {
    RestartSubBlockTimer();
  }
  Send(sdo::BlockAck(ackseq, transfer_.blksize));
}

// The last segment of a sub-block did not come within 70 % of the timeout: acknowledge what did,
// so the server resends the rest (mirrors the server's block download).
void SdoClient::OnSubBlockStalled() {
  if (transfer_.state == State::kBlockUploadSubBlock) AcknowledgeSubBlock();
}

void SdoClient::RestartSubBlockTimer() {
  if (options_.timeout > Duration::zero()) sub_block_timer_.StartAfter(options_.timeout * 7 / 10);
}

// End block upload request: 110n nn01 | CRC (LE16). Answered with A1h.
void SdoClient::OnBlockUploadEnd(const sdo::Payload& response) {
  auto& data = transfer_.data;
  const auto unused = sdo::BlockEndUnused(response[0]);
  if (unused > data.size()) return Fail(SdoAbort::kInvalidCommand);  // cannot happen: ≥ 1 segment came
  data.resize(data.size() - unused);
  if (transfer_.crc && Crc16Ccitt(data) != sdo::U16At(response, 1)) return Fail(SdoAbort::kCrcError);
  if (transfer_.size && data.size() != *transfer_.size) return Fail(SdoAbort::kTypeMismatch);
  if (data.size() > options_.max_upload_bytes) return Fail(SdoAbort::kOutOfMemory);
  const auto end = sdo::BlockEndResponse();
  Complete(SdoAbort::kNone, &end);
}

}  // namespace canfleet::canopen
