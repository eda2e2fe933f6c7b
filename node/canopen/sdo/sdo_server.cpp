// SDO server: COB-IDs, enabling, the dispatcher and the state shared by all transfer types
// (CiA 301 v4.2 §7.2.4). The protocols themselves are in expedited.cpp, segmented.cpp,
// block_download.cpp and block_upload.cpp.
#include "node/canopen/sdo/sdo_server.hpp"

#include <utility>

namespace canfleet::canopen {

namespace {

// SDO COB-ID entries (CiA 301 §7.5.2.33, 1200h sub1/sub2).
constexpr std::uint32_t kCobIdInvalid = 0x80000000;  // bit 31: 1 = SDO not valid
constexpr std::uint32_t kCobIdFrame = 0x20000000;    // bit 29: 1 = 29-bit CAN-ID
constexpr std::uint16_t kServerParameter = 0x1200;

bool ValidNodeId(std::uint8_t node_id) {
  return node_id >= 1 && node_id <= 127;
}

std::uint32_t CanIdOf(std::uint32_t cob_id) {
  return cob_id & ((cob_id & kCobIdFrame) ? CanFrame::kMaxExtendedId : CanFrame::kMaxStandardId);
}

}  // namespace

void AddSdoServerObjects(ObjectDictionary& od) {
  Object obj;
  obj.index = kServerParameter;
  obj.name = "SDO server parameter";
  obj.code = ObjectCode::kRecord;

  SubObject count;
  count.name = "Highest sub-index supported";
  count.type = DataType::kUnsigned8;
  count.access = Access::kConst;
  count.default_value = {2};

  SubObject rx;
  rx.name = "COB-ID client to server (rx)";
  rx.type = DataType::kUnsigned32;
  rx.access = Access::kRo;
  rx.default_value = EncodeLe<std::uint32_t>(sdo::kRequestCobIdBase);
  rx.default_adds_node_id = true;

  SubObject tx = rx;
  tx.name = "COB-ID server to client (tx)";
  tx.default_value = EncodeLe<std::uint32_t>(sdo::kResponseCobIdBase);

  obj.subs.emplace(0, std::move(count));
  obj.subs.emplace(1, std::move(rx));
  obj.subs.emplace(2, std::move(tx));
  od.Add(std::move(obj));
}

SdoServer::SdoServer(ObjectDictionary& od, BusPort& port, Scheduler& scheduler, SdoServerOptions options)
    : od_(od),
      port_(port),
      options_(options),
      timeout_(scheduler, [this] { OnTimeout(); }),
      sub_block_timer_(scheduler, [this] { OnSubBlockStalled(); }) {
  if (options_.block_size == 0) options_.block_size = 1;
  if (options_.block_size > sdo::kMaxBlockSize) options_.block_size = sdo::kMaxBlockSize;
  WatchParameterObject();
}

// ---- configuration -----------------------------------------------------------------------------

void SdoServer::SetNodeId(std::uint8_t node_id) {
  // Lely co_ssdo_update() aborts an ongoing transfer with "SDO connection not available" when the
  // channel is reconfigured; the frame goes out on the COB-ID the client is talking to.
  if (Busy()) Abort(SdoAbort::kNoResource);
  node_id_ = node_id;
  if (!ValidNodeId(node_id)) {
    ApplyCobIds(kCobIdInvalid, kCobIdInvalid);
    return;
  }
  WatchParameterObject();
  std::uint32_t request = sdo::kRequestCobIdBase + node_id;
  std::uint32_t response = sdo::kResponseCobIdBase + node_id;
  // 1200h sub1/sub2 are "$NODEID+600h"/"$NODEID+580h" (CiA 301 §7.5.2.33); the node-ID is applied
  // to their defaults and the result is what an SDO read of 1200h shows.
  if (SubObject* sub = od_.Find(kServerParameter, 1)) {
    Bytes value = sub->DefaultFor(node_id);
    request = static_cast<std::uint32_t>(DecodeUnsignedLe(value));
    (void)od_.Write(*sub, value, Origin::kDevice);
  }
  if (SubObject* sub = od_.Find(kServerParameter, 2)) {
    Bytes value = sub->DefaultFor(node_id);
    response = static_cast<std::uint32_t>(DecodeUnsignedLe(value));
    (void)od_.Write(*sub, value, Origin::kDevice);
  }
  ApplyCobIds(request, response);
}

void SdoServer::WatchParameterObject() {
  for (std::uint8_t i = 0; i < 2; ++i) {
    SubObject* sub = od_.Find(kServerParameter, static_cast<std::uint8_t>(i + 1));
    if (!sub || sub == watched_[i]) continue;
    sub->AddListener([this](SubObject&, Origin) { FollowParameterObject(); });
    watched_[i] = sub;
  }
}

// A device write or a RestoreDefaults of 1200h sub1/sub2 moves the server to the new COB-IDs.
void SdoServer::FollowParameterObject() {
  if (!ValidNodeId(node_id_)) return;
  const SubObject* rx = od_.Find(kServerParameter, 1);
  const SubObject* tx = od_.Find(kServerParameter, 2);
  ApplyCobIds(
      rx ? static_cast<std::uint32_t>(DecodeUnsignedLe(rx->value)) : sdo::kRequestCobIdBase + node_id_,
      tx ? static_cast<std::uint32_t>(DecodeUnsignedLe(tx->value)) : sdo::kResponseCobIdBase + node_id_);
}

void SdoServer::ApplyCobIds(std::uint32_t request, std::uint32_t response) {
  if (request == request_cob_id_ && response == response_cob_id_) return;
  if (Busy()) Abort(SdoAbort::kNoResource);
  request_cob_id_ = request;
  response_cob_id_ = response;
}

void SdoServer::SetEnabled(bool enabled) {
  enabled_ = enabled;
  if (!enabled) Finish();  // dropped silently: in stopped the node sends no SDO frames (§7.3.2.2)
}

// ---- receiving ---------------------------------------------------------------------------------

void SdoServer::AddListenedIds(std::vector<std::uint32_t>& ids) const {
  if ((request_cob_id_ & kCobIdInvalid) == 0 && (request_cob_id_ & kCobIdFrame) == 0)
    ids.push_back(CanIdOf(request_cob_id_));
}

bool SdoServer::OnFrame(const CanFrame& frame) {
  if (!enabled_ || (request_cob_id_ & kCobIdInvalid) || (response_cob_id_ & kCobIdInvalid)) return false;
  if (frame.error() || frame.id != CanIdOf(request_cob_id_)) return false;
  if (frame.extended() != ((request_cob_id_ & kCobIdFrame) != 0)) return false;
  // CiA 301 §7.2.4.3.1: SDO frames have 8 data bytes. CANopenNode's CO_SDO_receive() ignores
  // other lengths (and a remote frame carries no data), so the transfer state is untouched.
  if (frame.remote() || frame.dlc != 8) return true;
  Dispatch(frame.data);
  return true;
}

void SdoServer::Dispatch(const sdo::Payload& request) {
  using sdo::BlockSubcommand;
  using sdo::ClientCommand;
  const std::uint8_t cs = request[0];

  // §7.2.4.3.10: inside a sub-block byte 0 is c|seqno, not a command specifier. Only 80h (c = 1
  // with seqno 0, which no segment can carry) is taken as the client's abort (CANopenNode, Lely).
  if (transfer_.state == State::kBlockDownloadSubBlock) {
    if (cs == sdo::kAbortCommand) {
      Finish();
    } else {
      OnBlockDownloadSegment(request);
    }
    return;
  }

  switch (sdo::ClientCommandOf(cs)) {
    case ClientCommand::kAbort:
      // §7.2.4.3.17: an abort is unconfirmed; it ends any transfer without a reply.
      Finish();
      return;
    case ClientCommand::kInitiateDownload:
      OnInitiateDownload(request);
      return;
    case ClientCommand::kInitiateUpload:
      OnInitiateUpload(request);
      return;
    case ClientCommand::kDownloadSegment:
      if (transfer_.state == State::kDownloadSegments) return OnDownloadSegment(request);
      break;
    case ClientCommand::kUploadSegment:
      if (transfer_.state == State::kUploadSegments) return OnUploadSegmentRequest(request);
      break;
    case ClientCommand::kBlockDownload:
      // 110x xcs0 initiates, 110n nnx1 ends (bit 0 is the sub-command).
      if ((cs & 0x01) == 0) return OnBlockDownloadInitiate(request);
      if (transfer_.state == State::kBlockDownloadEnd) return OnBlockDownloadEnd(request);
      break;
    case ClientCommand::kBlockUpload:
      switch (sdo::BlockSubcommandOf(cs)) {
        case BlockSubcommand::kInitiate:
          return OnBlockUploadInitiate(request);
        case BlockSubcommand::kStartUpload:
          if (transfer_.state == State::kBlockUploadStart) return OnBlockUploadStart();
          break;
        case BlockSubcommand::kAck:
          if (transfer_.state == State::kBlockUploadSubBlock) return OnBlockUploadAck(request);
          break;
        case BlockSubcommand::kEnd:
          // §7.2.4.3.15: the client's end response completes the block upload.
          if (transfer_.state == State::kBlockUploadEnd) return Finish();
          break;
      }
      break;
    case ClientCommand::kInvalid:
      break;
  }
  // Unknown specifier, or one that does not fit the transfer in progress (including a segment
  // with no transfer at all): §7.2.4.3.17 abort code 05040001.
  Abort(SdoAbort::kInvalidCommand);
}

// ---- transfer state ----------------------------------------------------------------------------

void SdoServer::Start(std::uint16_t index, std::uint8_t sub_index) {
  Finish();
  transfer_.index = index;
  transfer_.sub_index = sub_index;
}

void SdoServer::Enter(State state) {
  transfer_.state = state;
  RestartTimeout();
}

void SdoServer::Finish() {
  timeout_.Cancel();
  sub_block_timer_.Cancel();
  transfer_ = Transfer{};  // also frees the buffer of a large transfer
  ++generation_;
}

void SdoServer::Abort(SdoAbort code) {
  const auto frame = sdo::AbortTransfer(transfer_.index, transfer_.sub_index, code);
  Finish();
  Send(frame);
}

void SdoServer::Send(const sdo::Payload& payload) {
  if (response_cob_id_ & kCobIdInvalid) return;
  CanFrame frame;
  frame.id = CanIdOf(response_cob_id_);
  frame.flags = (response_cob_id_ & kCobIdFrame) ? CanFrame::kExtended : 0;
  frame.dlc = 8;
  frame.data = payload;
  port_.Send(frame);
}

void SdoServer::RestartTimeout() {
  if (options_.timeout > Duration::zero()) timeout_.StartAfter(options_.timeout);
}

void SdoServer::RestartSubBlockTimer() {
  if (options_.timeout > Duration::zero()) sub_block_timer_.StartAfter(options_.timeout * 7 / 10);
}

// The SDO timeout of CiA 301 §7.2.4.3.17 (05040000): no frame from the client for `timeout`.
void SdoServer::OnTimeout() {
  if (Busy()) Abort(SdoAbort::kTimeout);
}

// ---- shared download helpers -------------------------------------------------------------------

// Checks made when a segmented or block download starts, so the client does not send data that
// can only be refused: the object exists and is writable (the OD checks these again when the
// value is committed) and an indicated size fits the object (CANopenNode does the same).
SdoAbort SdoServer::CheckDownloadTarget(std::optional<std::uint32_t> size) {
  SubObject* sub = nullptr;
  if (auto rc = od_.Lookup(transfer_.index, transfer_.sub_index, sub); rc != SdoAbort::kNone) return rc;
  if (!IsWritable(sub->access)) return SdoAbort::kReadOnly;
  if (!size) return SdoAbort::kNone;
  if (auto fixed = FixedSize(sub->type)) {
    if (*size > *fixed) return SdoAbort::kLengthTooHigh;
    if (*size < *fixed) return SdoAbort::kLengthTooLow;
  }
  if (*size > options_.max_transfer_bytes) return SdoAbort::kOutOfMemory;
  return SdoAbort::kNone;
}

// Writes the complete download to the OD in one go (access, length, limits and validators are the
// OD's), then confirms with `response` or aborts with the OD's code.
void SdoServer::Commit(const sdo::Payload& response) {
  const Bytes data = std::move(transfer_.data);  // a validator or listener may end the transfer
  const auto generation = generation_;
  const SdoAbort rc = od_.Write(transfer_.index, transfer_.sub_index, data, Origin::kSdo);
  if (generation != generation_) return;  // a listener reset or disabled the server
  if (rc != SdoAbort::kNone) return Abort(rc);
  Finish();
  Send(response);
}

}  // namespace canfleet::canopen
