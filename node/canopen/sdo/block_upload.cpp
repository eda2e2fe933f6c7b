// SDO block upload (CiA 301 v4.2 §7.2.4.3.12–15): the server sends sub-blocks of up to the
// client's blksize segments; the client acknowledges each with the last segment it received in
// order and the server resends from there. The end frame says how much of the last segment is
// padding and carries the CRC.
#include <algorithm>
#include <array>
#include <span>

#include "node/canopen/sdo/crc16_ccitt.hpp"
#include "node/canopen/sdo/sdo_server.hpp"

namespace canfleet::canopen {

// Initiate block upload, client → server:
//   byte 0   1010 0c00   c = client CRC support
//   byte 1-2 index, byte 3 sub-index, byte 4 blksize (1..127), byte 5 pst (0 = no switch)
// Response 1100 0s10 | index | sub-index | size (LE32), sc = 1: a CRC is used when cc = 1.
void SdoServer::OnBlockUploadInitiate(const sdo::Payload& request) {
  Start(sdo::IndexOf(request), sdo::SubIndexOf(request));
  const std::uint8_t blksize = request[4];
  const std::uint8_t pst = request[5];
  if (blksize == 0 || blksize > sdo::kMaxBlockSize) return Abort(SdoAbort::kInvalidBlockSize);

  Bytes value;
  const auto generation = generation_;
  const SdoAbort rc = od_.Read(transfer_.index, transfer_.sub_index, value, Origin::kSdo);
  if (generation != generation_) return;
  if (rc != SdoAbort::kNone) return Abort(rc);
  transfer_.data = std::move(value);

  // Protocol switch (§7.2.4.3.13): with pst > 0 and no more than pst bytes the server may answer
  // with the initiate upload response of the normal protocol (Lely does).
  if (pst > 0 && transfer_.data.size() <= pst) return RespondToUpload();

  transfer_.crc = (request[0] & sdo::kBlockCrc) != 0;
  transfer_.blksize = blksize;
  transfer_.offset = 0;
  Enter(State::kBlockUploadStart);
  Send(sdo::BlockUploadInitiateResponse(transfer_.index, transfer_.sub_index, true,
                                        static_cast<std::uint32_t>(transfer_.data.size())));
}

// Start block upload, client → server: A3h. The first sub-block follows.
void SdoServer::OnBlockUploadStart() {
  RestartTimeout();
  SendSubBlock();
}

// Upload sub-block, server → client: up to blksize segments `c << 7 | seqno, 7 bytes` from the
// first byte not yet acknowledged; the segment holding the last byte has c = 1 (an empty value
// still sends one segment). The frames are built first, so the state is final before any goes out.
void SdoServer::SendSubBlock() {
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
  transfer_.state = State::kBlockUploadSubBlock;
  const auto generation = ++generation_;
  for (std::size_t i = 0; i < count && generation == generation_; ++i)
    Send(frames[i]);
}

// Block upload response, client → server: A2h | ackseq | blksize of the next sub-block.
void SdoServer::OnBlockUploadAck(const sdo::Payload& request) {
  const std::uint8_t ackseq = request[1];
  const std::uint8_t blksize = request[2];
  // The client cannot have received a segment that was not sent (§7.2.4.3.14).
  if (ackseq > transfer_.seqno) return Abort(SdoAbort::kInvalidSequence);
  if (blksize == 0 || blksize > sdo::kMaxBlockSize) return Abort(SdoAbort::kInvalidBlockSize);
  RestartTimeout();
  const auto& data = transfer_.data;
  transfer_.offset = std::min(data.size(), transfer_.offset + std::size_t{ackseq} * sdo::kSegmentBytes);
  transfer_.blksize = blksize;

  if (ackseq == transfer_.seqno && transfer_.last) {
    // End block upload, server → client (§7.2.4.3.15): 110n nn01 | CRC (LE16, 0 without CRC).
    const auto crc = transfer_.crc ? Crc16Ccitt(data) : std::uint16_t{0};
    transfer_.state = State::kBlockUploadEnd;
    Send(sdo::BlockEnd(sdo::UnusedInLastSegment(data.size()), crc));
    return;
  }
  SendSubBlock();
}

}  // namespace canfleet::canopen
