// Segmented SDO download and upload (CiA 301 v4.2 §7.2.4.3.2–4 and §7.2.4.3.5–7): seven data
// bytes per segment, each confirmed, with a toggle bit that alternates from 0.
#include <algorithm>
#include <span>

#include "node/canopen/sdo/sdo_server.hpp"

namespace canfleet::canopen {

// The initiate request had e = 0. The size, when indicated (s = 1), must fit the object.
void SdoServer::StartSegmentedDownload(std::optional<std::uint32_t> size) {
  if (auto rc = CheckDownloadTarget(size); rc != SdoAbort::kNone) return Abort(rc);
  transfer_.size = size;
  if (size) transfer_.data.reserve(*size);  // ≤ max_transfer_bytes, checked above
  transfer_.toggle = false;
  Enter(State::kDownloadSegments);
  Send(sdo::InitiateDownloadResponse(transfer_.index, transfer_.sub_index));
}

// Download SDO segment, client → server:
//   byte 0   000t nnnc   t = toggle, n = bytes of 1..7 without data, c = 1: last segment
//   byte 1-7 data
// Response 001t 0000 (20h/30h) with the toggle of the request.
void SdoServer::OnDownloadSegment(const sdo::Payload& request) {
  const std::uint8_t cs = request[0];
  const bool toggle = (cs & sdo::kToggle) != 0;
  if (toggle != transfer_.toggle) return Abort(SdoAbort::kToggleBit);  // §7.2.4.3.4

  auto& data = transfer_.data;
  const auto n = sdo::SegmentSize(cs);
  data.insert(data.end(), request.begin() + 1, request.begin() + 1 + static_cast<std::ptrdiff_t>(n));
  // More data than indicated: the total does not match the initiate (06070010).
  if (transfer_.size && data.size() > *transfer_.size) return Abort(SdoAbort::kTypeMismatch);
  if (data.size() > options_.max_transfer_bytes) return Abort(SdoAbort::kOutOfMemory);

  if (cs & sdo::kLastSegment) {
    if (transfer_.size && data.size() != *transfer_.size) return Abort(SdoAbort::kTypeMismatch);
    return Commit(sdo::DownloadSegmentResponse(toggle));
  }
  transfer_.toggle = !toggle;
  RestartTimeout();
  Send(sdo::DownloadSegmentResponse(toggle));
}

// The value does not fit in an expedited response (or is empty): initiate response 41h with the
// size, then the client asks for each segment.
void SdoServer::StartSegmentedUpload() {
  transfer_.offset = 0;
  transfer_.toggle = false;
  Enter(State::kUploadSegments);
  Send(sdo::InitiateUploadSegmented(transfer_.index, transfer_.sub_index,
                                    static_cast<std::uint32_t>(transfer_.data.size())));
}

// Upload SDO segment request, client → server: 011t 0000 (60h/70h).
// Response 000t nnnc | data: the next seven bytes at most, c = 1 on the one holding the last byte.
void SdoServer::OnUploadSegmentRequest(const sdo::Payload& request) {
  const bool toggle = (request[0] & sdo::kToggle) != 0;
  if (toggle != transfer_.toggle) return Abort(SdoAbort::kToggleBit);  // §7.2.4.3.7

  const auto& data = transfer_.data;
  const auto remaining = data.size() - transfer_.offset;
  const auto n = std::min(remaining, sdo::kSegmentBytes);
  const bool last = remaining <= sdo::kSegmentBytes;
  const auto response = sdo::Segment(toggle, std::span(data).subspan(transfer_.offset, n), last);
  if (last) {
    Finish();
    Send(response);
    return;
  }
  transfer_.offset += n;
  transfer_.toggle = !toggle;
  RestartTimeout();
  Send(response);
}

}  // namespace canfleet::canopen
