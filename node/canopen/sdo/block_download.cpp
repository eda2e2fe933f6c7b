// SDO block download (CiA 301 v4.2 §7.2.4.3.8–11): the client sends sub-blocks of up to blksize
// segments without waiting; the server acknowledges each sub-block with the sequence number of the
// last segment it received in order, and the client resends from there. An optional CRC over the
// whole data set is checked at the end.
#include "node/canopen/sdo/crc16_ccitt.hpp"
#include "node/canopen/sdo/sdo_server.hpp"

namespace canfleet::canopen {

// Initiate block download, client → server:
//   byte 0   110x xcs0   c = client CRC support (cc), s = size indicated
//   byte 1-2 index, byte 3 sub-index, byte 4-7 size (LE32) if s = 1
// Response 1010 0s00 | index | sub-index | blksize: the server always offers a CRC (sc = 1), so
// one is used exactly when the client asked for it.
void SdoServer::OnBlockDownloadInitiate(const sdo::Payload& request) {
  const std::uint8_t cs = request[0];
  Start(sdo::IndexOf(request), sdo::SubIndexOf(request));
  const auto size = (cs & sdo::kBlockSize) ? std::optional(sdo::U32At(request, 4)) : std::nullopt;
  if (auto rc = CheckDownloadTarget(size); rc != SdoAbort::kNone) return Abort(rc);
  transfer_.size = size;
  if (size) transfer_.data.reserve(*size + sdo::kSegmentBytes);  // ≤ max_transfer_bytes + 7
  transfer_.crc = (cs & sdo::kBlockCrc) != 0;
  transfer_.blksize = options_.block_size;
  transfer_.seqno = 0;
  Enter(State::kBlockDownloadSubBlock);
  RestartSubBlockTimer();
  Send(sdo::BlockDownloadInitiateResponse(transfer_.index, transfer_.sub_index, true, transfer_.blksize));
}

// Download sub-block segment, client → server: byte 0 = c << 7 | seqno (1..blksize), bytes 1-7 data.
// No response, except the acknowledgement after seqno = blksize or the segment with c = 1.
void SdoServer::OnBlockDownloadSegment(const sdo::Payload& request) {
  const std::uint8_t seqno = request[0] & sdo::kSeqnoMask;
  const bool last = (request[0] & sdo::kBlockLast) != 0;
  // A seqno that cannot occur in this sub-block is a protocol error (Lely aborts with 05040003).
  if (seqno == 0 || seqno > transfer_.blksize) return Abort(SdoAbort::kInvalidSequence);
  RestartTimeout();

  // Only the next segment in sequence is kept; a lost segment makes every later one of the
  // sub-block useless, and the acknowledgement tells the client to resend them (§7.2.4.3.10).
  if (seqno == transfer_.seqno + 1) {
    auto& data = transfer_.data;
    data.insert(data.end(), request.begin() + 1, request.end());
    transfer_.seqno = seqno;
    transfer_.last = last;
    // Bounded memory: at most 6 bytes of padding in the last segment (7 for an empty download).
    if (transfer_.size && data.size() > std::size_t{*transfer_.size} + sdo::kSegmentBytes) {
      return Abort(SdoAbort::kTypeMismatch);
    }
    if (data.size() > options_.max_transfer_bytes + sdo::kSegmentBytes) return Abort(SdoAbort::kOutOfMemory);
  }

  if (seqno == transfer_.blksize || last) return AcknowledgeSubBlock();
  RestartSubBlockTimer();
}

// Block download response, server → client: A2h | ackseq | blksize. After the segment with c = 1
// was received in order, the client continues with the end request; otherwise a new sub-block
// starts at seqno 1 with the data after ackseq.
void SdoServer::AcknowledgeSubBlock() {
  const std::uint8_t ackseq = transfer_.seqno;
  transfer_.seqno = 0;
  transfer_.blksize = options_.block_size;
  if (transfer_.last) {
    sub_block_timer_.Cancel();
    transfer_.state = State::kBlockDownloadEnd;
  } else {
    RestartSubBlockTimer();
  }
  Send(sdo::BlockAck(ackseq, transfer_.blksize));
}

// No segment for 70 % of the SDO timeout in a sub-block: the segment that should have ended it was
// probably lost. Acknowledging what arrived lets the client resend the rest (CANopenNode's
// sub-block timeout); the SDO timeout still runs from the client's last frame.
void SdoServer::OnSubBlockStalled() {
  if (transfer_.state == State::kBlockDownloadSubBlock) AcknowledgeSubBlock();
}

// End block download, client → server:
//   byte 0   110n nn01   n = bytes of the last segment without data
//   byte 1-2 CRC (LE16) over the whole data set if both sides support it
// Response A1h, after the value was written to the OD.
void SdoServer::OnBlockDownloadEnd(const sdo::Payload& request) {
  auto& data = transfer_.data;
  const auto unused = sdo::BlockEndUnused(request[0]);
  if (unused > data.size()) return Abort(SdoAbort::kInvalidCommand);  // cannot happen: ≥ 1 segment came
  data.resize(data.size() - unused);
  if (transfer_.crc && Crc16Ccitt(data) != sdo::U16At(request, 1)) return Abort(SdoAbort::kCrcError);
  if (transfer_.size && data.size() != *transfer_.size) return Abort(SdoAbort::kTypeMismatch);
  if (data.size() > options_.max_transfer_bytes) return Abort(SdoAbort::kOutOfMemory);
  Commit(sdo::BlockEndResponse());
}

}  // namespace canfleet::canopen
