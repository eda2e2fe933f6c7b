// SDO initiate download / initiate upload and the expedited transfers (CiA 301 v4.2 §7.2.4.3.3
// and §7.2.4.3.6). A request that does not fit in one frame continues in segmented.cpp.
#include <algorithm>
#include <span>

#include "node/canopen/sdo/sdo_server.hpp"

namespace canfleet::canopen {

// Initiate SDO download, client → server:
//   byte 0   001x nnes   e = expedited, s = size indicated, n = bytes of 4..7 without data (e = s = 1)
//   byte 1-2 index, byte 3 sub-index
//   byte 4-7 e = 1: the data; e = 0, s = 1: the size of the segmented download (LE32)
// Response 60h | index | sub-index | 0.
void SdoServer::OnInitiateDownload(const sdo::Payload& request) {
  const std::uint8_t cs = request[0];
  Start(sdo::IndexOf(request), sdo::SubIndexOf(request));
  if (!(cs & sdo::kExpedited)) {
    StartSegmentedDownload((cs & sdo::kSizeIndicated) ? std::optional(sdo::U32At(request, 4)) : std::nullopt);
    return;
  }

  SubObject* sub = nullptr;
  if (auto rc = od_.Lookup(transfer_.index, transfer_.sub_index, sub); rc != SdoAbort::kNone)
    return Abort(rc);
  // With s = 1 the size is 4 − n. With s = 0 (22h) the size is not given: the object's own size
  // if that fits in the frame (CANopenNode does the same), else all four bytes; a fixed-size
  // object then reports too high / too low through the OD's length check.
  std::size_t size = 4;
  if (cs & sdo::kSizeIndicated) {
    size = sdo::ExpeditedSize(cs);
  } else if (auto fixed = FixedSize(sub->type)) {
    size = std::min<std::size_t>(*fixed, 4);
  }
  const auto generation = generation_;
  const SdoAbort rc = od_.Write(*sub, std::span(request).subspan(4, size), Origin::kSdo);
  if (generation != generation_) return;  // a listener reset or disabled the server
  if (rc != SdoAbort::kNone) return Abort(rc);
  const auto response = sdo::InitiateDownloadResponse(transfer_.index, transfer_.sub_index);
  Finish();
  Send(response);
}

// Initiate SDO upload, client → server: 40h | index | sub-index | reserved.
// The value is read once here (access, existence and read hooks are the OD's); the segments of a
// segmented upload are cut from this snapshot, so the client sees one consistent value.
void SdoServer::OnInitiateUpload(const sdo::Payload& request) {
  Start(sdo::IndexOf(request), sdo::SubIndexOf(request));
  Bytes value;
  const auto generation = generation_;
  const SdoAbort rc = od_.Read(transfer_.index, transfer_.sub_index, value, Origin::kSdo);
  if (generation != generation_) return;
  if (rc != SdoAbort::kNone) return Abort(rc);
  transfer_.data = std::move(value);
  RespondToUpload();
}

// Initiate SDO upload response (also the answer to a block upload below the protocol switch
// threshold, §7.2.4.3.13):
//   1..4 bytes: 010x nn11 | index | sub-index | data      (43h/47h/4Bh/4Fh), expedited
//   otherwise:  0100 0001 | index | sub-index | size LE32 (41h), segmented follows
void SdoServer::RespondToUpload() {
  const auto& data = transfer_.data;
  if (!data.empty() && data.size() <= 4) {
    const auto response = sdo::InitiateUploadExpedited(transfer_.index, transfer_.sub_index, data);
    Finish();
    Send(response);
    return;
  }
  StartSegmentedUpload();
}

}  // namespace canfleet::canopen
