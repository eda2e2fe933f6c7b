// SDO client: requests, response dispatch, expedited and segmented transfers (CiA 301 v4.2
// §7.2.4.3.2–7). Block transfers are in sdo_client_block.cpp.
#include "node/canopen/sdo/sdo_client.hpp"

#include <algorithm>
#include <limits>
#include <utility>

namespace canfleet::canopen {

SdoClient::SdoClient(BusPort& port, Scheduler& scheduler, SdoClientOptions options)
    : port_(port),
      options_(options),
      timeout_(scheduler,
               [this] {
                 if (Busy()) Fail(SdoAbort::kTimeout);
               }),
      sub_block_timer_(scheduler, [this] { OnSubBlockStalled(); }) {
  options_.block_size = std::clamp<std::uint8_t>(options_.block_size, 1, sdo::kMaxBlockSize);
}

// ---- requests ----------------------------------------------------------------------------------

bool SdoClient::Begin(std::uint8_t node_id, std::uint16_t index, std::uint8_t sub_index) {
  if (Busy() || node_id < 1 || node_id > 127) return false;
  transfer_ = Transfer{};
  transfer_.node_id = node_id;
  transfer_.index = index;
  transfer_.sub_index = sub_index;
  return true;
}

bool SdoClient::Upload(std::uint8_t node_id, std::uint16_t index, std::uint8_t sub_index, SdoMode mode,
                       SdoUploadCallback done) {
  if (!Begin(node_id, index, sub_index)) return false;
  transfer_.upload_done = std::move(done);
  if (mode == SdoMode::kBlock) {
    Await(State::kBlockUploadInitiate);
    Send(sdo::BlockUploadInitiate(index, sub_index, options_.crc, options_.block_size, options_.pst));
  } else {
    Await(State::kInitiateUpload);
    Send(sdo::InitiateUploadRequest(index, sub_index));
  }
  return true;
}

bool SdoClient::Download(std::uint8_t node_id, std::uint16_t index, std::uint8_t sub_index,
                         std::span<const std::uint8_t> data, SdoMode mode, SdoDownloadCallback done) {
  if (data.size() > std::numeric_limits<std::uint32_t>::max()) return false;
  if (!Begin(node_id, index, sub_index)) return false;
  transfer_.download_done = std::move(done);
  transfer_.data.assign(data.begin(), data.end());
  const auto size = static_cast<std::uint32_t>(data.size());
  switch (mode) {
    case SdoMode::kBlock:
      Await(State::kBlockDownloadInitiate);
      Send(sdo::BlockDownloadInitiate(index, sub_index, options_.crc, size));
      return true;
    case SdoMode::kAuto:
      if (size >= 1 && size <= 4) {
        transfer_.last = true;  // the data travels in the initiate request
        Await(State::kInitiateDownload);
        Send(sdo::InitiateDownloadExpedited(index, sub_index, data));
        return true;
      }
      [[fallthrough]];
    case SdoMode::kSegmented:
      Await(State::kInitiateDownload);
      Send(sdo::InitiateDownloadSegmented(index, sub_index, size));
      return true;
  }
  return true;
}

void SdoClient::Abort(SdoAbort code) {
  if (Busy()) Fail(code);
}

// ---- frames ------------------------------------------------------------------------------------

bool SdoClient::OnFrame(const CanFrame& frame) {
  if (!Busy() || frame.error() || frame.extended()) return false;
  if (frame.id != sdo::kResponseCobIdBase + transfer_.node_id) return false;
  if (frame.remote() || frame.dlc != 8) return true;  // as the server: not an SDO frame (§7.2.4.3.1)
  Dispatch(frame.data);
  return true;
}

void SdoClient::Dispatch(const sdo::Payload& response) {
  using sdo::BlockSubcommand;
  using sdo::ServerCommand;
  const std::uint8_t cs = response[0];
  // Inside an upload sub-block byte 0 is c|seqno; 80h (seqno 0) can only be the server's abort.
  if (transfer_.state == State::kBlockUploadSubBlock) {
    if (cs == sdo::kAbortCommand) return Complete(sdo::AbortCodeOf(response));
    return OnBlockUploadSegment(response);
  }
  const ServerCommand scs = sdo::ServerCommandOf(cs);
  // §7.2.4.3.17: the server's abort ends the transfer; it is not confirmed.
  if (scs == ServerCommand::kAbort) return Complete(sdo::AbortCodeOf(response));

  switch (transfer_.state) {
    case State::kInitiateDownload:
      if (scs == ServerCommand::kInitiateDownload) return OnInitiateDownloadResponse(response);
      break;
    case State::kDownloadSegments:
      if (scs == ServerCommand::kDownloadSegment) return OnDownloadSegmentResponse(response);
      break;
    case State::kInitiateUpload:
      if (scs == ServerCommand::kInitiateUpload) return OnInitiateUploadResponse(response);
      break;
    case State::kUploadSegments:
      if (scs == ServerCommand::kUploadSegment) return OnUploadSegment(response);
      break;
    case State::kBlockDownloadInitiate:
      if (scs == ServerCommand::kBlockDownload && sdo::BlockSubcommandOf(cs) == BlockSubcommand::kInitiate) {
        return OnBlockDownloadInitiateResponse(response);
      }
      break;
    case State::kBlockDownloadSubBlock:
      if (scs == ServerCommand::kBlockDownload && sdo::BlockSubcommandOf(cs) == BlockSubcommand::kAck) {
        return OnBlockDownloadAck(response);
      }
      break;
    case State::kBlockDownloadEnd:
      if (scs == ServerCommand::kBlockDownload && sdo::BlockSubcommandOf(cs) == BlockSubcommand::kEnd) {
        return Complete(SdoAbort::kNone);
      }
      break;
    case State::kBlockUploadInitiate:
      if (scs == ServerCommand::kBlockUpload && (cs & 0x01) == 0)
        return OnBlockUploadInitiateResponse(response);
      // Protocol switch (§7.2.4.3.13): the server answered with a normal upload.
      if (scs == ServerCommand::kInitiateUpload) return OnInitiateUploadResponse(response);
      break;
    case State::kBlockUploadEnd:
      if (scs == ServerCommand::kBlockUpload && (cs & 0x01) == 1) return OnBlockUploadEnd(response);
      break;
    case State::kIdle:
    case State::kBlockUploadSubBlock:
      break;
  }
  Fail(SdoAbort::kInvalidCommand);
}

// ---- shared state ------------------------------------------------------------------------------

void SdoClient::SendTo(std::uint8_t node_id, const sdo::Payload& payload) {
  CanFrame frame;
  frame.id = sdo::kRequestCobIdBase + node_id;
  frame.dlc = 8;
  frame.data = payload;
  port_.Send(frame);
}

void SdoClient::RestartTimeout() {
  if (options_.timeout > Duration::zero()) timeout_.StartAfter(options_.timeout);
}

void SdoClient::Await(State state) {
  transfer_.state = state;
  RestartTimeout();
}

// Ends the transfer before anything else happens, so `last_frame` and the callback (which may
// start the next transfer) see an idle client.
void SdoClient::Complete(SdoAbort result, const sdo::Payload* last_frame) {
  timeout_.Cancel();
  sub_block_timer_.Cancel();
  Transfer done = std::move(transfer_);
  transfer_ = Transfer{};
  ++generation_;
  if (last_frame) SendTo(done.node_id, *last_frame);
  if (done.upload_done) {
    done.upload_done(result, result == SdoAbort::kNone ? std::move(done.data) : Bytes{});
  } else if (done.download_done) {
    done.download_done(result);
  }
}

void SdoClient::Fail(SdoAbort code) {
  const auto frame = sdo::AbortTransfer(transfer_.index, transfer_.sub_index, code);
  Complete(code, &frame);
}

// A response for another object is not ours to continue (CANopenNode's client aborts with
// 06040043, general parameter incompatibility).
bool SdoClient::MultiplexerMatches(const sdo::Payload& response) const {
  return sdo::IndexOf(response) == transfer_.index && sdo::SubIndexOf(response) == transfer_.sub_index;
}

// ---- upload ------------------------------------------------------------------------------------

// Initiate upload response: 010x nnes | index | sub-index | data (e = 1) or size (e = 0, s = 1).
void SdoClient::OnInitiateUploadResponse(const sdo::Payload& response) {
  if (!MultiplexerMatches(response)) return Fail(SdoAbort::kParameterIncompatible);
  const std::uint8_t cs = response[0];
  if (cs & sdo::kExpedited) {
    // Without s the size is unspecified: all four bytes are taken.
    const std::size_t n = (cs & sdo::kSizeIndicated) ? sdo::ExpeditedSize(cs) : 4;
    transfer_.data.assign(response.begin() + 4, response.begin() + 4 + static_cast<std::ptrdiff_t>(n));
    return Complete(SdoAbort::kNone);
  }
  if (cs & sdo::kSizeIndicated) {
    const std::uint32_t size = sdo::U32At(response, 4);
    if (size > options_.max_upload_bytes) return Fail(SdoAbort::kOutOfMemory);
    transfer_.size = size;
    transfer_.data.reserve(size);
  }
  transfer_.toggle = false;
  Await(State::kUploadSegments);
  Send(sdo::UploadSegmentRequest(false));
}

// Upload segment response: 000t nnnc | data.
void SdoClient::OnUploadSegment(const sdo::Payload& response) {
  const std::uint8_t cs = response[0];
  if (((cs & sdo::kToggle) != 0) != transfer_.toggle) return Fail(SdoAbort::kToggleBit);
  auto& data = transfer_.data;
  const auto n = sdo::SegmentSize(cs);
  data.insert(data.end(), response.begin() + 1, response.begin() + 1 + static_cast<std::ptrdiff_t>(n));
  if (transfer_.size && data.size() > *transfer_.size) return Fail(SdoAbort::kTypeMismatch);
  if (data.size() > options_.max_upload_bytes) return Fail(SdoAbort::kOutOfMemory);
  if (cs & sdo::kLastSegment) {
    if (transfer_.size && data.size() != *transfer_.size) return Fail(SdoAbort::kTypeMismatch);
    return Complete(SdoAbort::kNone);
  }
  transfer_.toggle = !transfer_.toggle;
  Await(State::kUploadSegments);
  Send(sdo::UploadSegmentRequest(transfer_.toggle));
}

// ---- download ----------------------------------------------------------------------------------

void SdoClient::OnInitiateDownloadResponse(const sdo::Payload& response) {
  if (!MultiplexerMatches(response)) return Fail(SdoAbort::kParameterIncompatible);
  if (transfer_.last) return Complete(SdoAbort::kNone);  // expedited: done
  transfer_.toggle = false;
  transfer_.offset = 0;
  SendDownloadSegment();
}

// Download segment: 000t nnnc | up to seven bytes; c = 1 on the one with the last byte (an empty
// value is one segment with n = 7).
void SdoClient::SendDownloadSegment() {
  const auto& data = transfer_.data;
  const auto remaining = data.size() - transfer_.offset;
  const auto n = std::min(remaining, sdo::kSegmentBytes);
  transfer_.last = remaining <= sdo::kSegmentBytes;
  const auto segment =
      sdo::Segment(transfer_.toggle, std::span(data).subspan(transfer_.offset, n), transfer_.last);
  transfer_.offset += n;
  Await(State::kDownloadSegments);
  Send(segment);
}

// Download segment response: 001t 0000 with the toggle of the segment it confirms.
void SdoClient::OnDownloadSegmentResponse(const sdo::Payload& response) {
  if (((response[0] & sdo::kToggle) != 0) != transfer_.toggle) return Fail(SdoAbort::kToggleBit);
  if (transfer_.last) return Complete(SdoAbort::kNone);
  transfer_.toggle = !transfer_.toggle;
  SendDownloadSegment();
}

}  // namespace canfleet::canopen
