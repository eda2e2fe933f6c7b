#pragma once
/// @file An asynchronous SDO client (CiA 301 v4.2 §7.2.4): expedited, segmented and block
/// upload/download to the default SDO server of any node (COB-IDs 600h+id / 580h+id), one
/// transfer at a time, with its own timeout. It is the test client of SdoServer and the engine of
/// the orchestrator's `canfleet sdo read/write`.
///
/// Completion is reported exactly once per accepted request, through the callback, with the
/// value (upload) or the abort code — the server's, or the one this client sent. The callback may
/// run inside Upload()/Download() or OnFrame() (a loopback bus answers synchronously) and may start
/// the next transfer.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>

#include "bus/bus_port.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/od/abort_code.hpp"
#include "node/canopen/od/value.hpp"
#include "node/canopen/sdo/sdo_protocol.hpp"

namespace canfleet::canopen {

/// How a transfer travels.
enum class SdoMode : std::uint8_t {
  kAuto,       ///< download: expedited for 1..4 bytes, else segmented; upload: the server chooses
               ///< expedited (≤ 4 bytes) or segmented
  kSegmented,  ///< download: segmented even for 1..4 bytes; upload: as kAuto
  kBlock,      ///< block download / block upload (§7.2.4.3.8–15)
};

struct SdoClientOptions {
  /// Longest wait for the server's next frame; on expiry abort 05040000 is sent and reported.
  /// Zero or negative: no timeout.
  Duration timeout = std::chrono::seconds(1);
  /// Segments per sub-block the client accepts in a block upload, 1..127 (others are clamped).
  std::uint8_t block_size = sdo::kMaxBlockSize;
  /// Protocol switch threshold offered in a block upload (§7.2.4.3.13): the server may answer a
  /// value of at most `pst` bytes with a normal upload. 0 = always block.
  std::uint8_t pst = 0;
  /// Ask for a CRC in block transfers (used when the server supports it too).
  bool crc = true;
  /// An upload whose indicated or received size exceeds this aborts with 05040005.
  std::size_t max_upload_bytes = 16u << 20;
};

/// Upload completion: kNone and the value, or the abort code and no data.
using SdoUploadCallback = std::function<void(SdoAbort abort, Bytes data)>;
/// Download completion: kNone, or the abort code.
using SdoDownloadCallback = std::function<void(SdoAbort abort)>;

class SdoClient {
 public:
  /// @param port where requests are sent; the owner routes received frames to OnFrame().
  /// @param scheduler runs the timeout.
  SdoClient(BusPort& port, Scheduler& scheduler, SdoClientOptions options = {});
  SdoClient(const SdoClient&) = delete;
  SdoClient& operator=(const SdoClient&) = delete;

  /// Reads `index`:`sub_index` of node `node_id` (1..127). Returns false, without calling `done`,
  /// when a transfer is in progress or the node-ID is invalid.
  bool Upload(std::uint8_t node_id, std::uint16_t index, std::uint8_t sub_index, SdoMode mode,
              SdoUploadCallback done);

  /// Writes `data` to `index`:`sub_index` of node `node_id` (1..127). Returns false, without
  /// calling `done`, when a transfer is in progress, the node-ID is invalid or `data` is larger
  /// than an SDO size field can say (4 GiB).
  bool Download(std::uint8_t node_id, std::uint16_t index, std::uint8_t sub_index,
                std::span<const std::uint8_t> data, SdoMode mode, SdoDownloadCallback done);

  /// Aborts the transfer in progress: sends the abort frame with `code` and reports `code`.
  void Abort(SdoAbort code = SdoAbort::kGeneralError);

  /// Handles a received frame. Returns true when it is the response COB-ID of the transfer in
  /// progress (frames with DLC ≠ 8 are then ignored, as the server does).
  bool OnFrame(const CanFrame& frame);

  bool Busy() const { return transfer_.state != State::kIdle; }

 private:
  enum class State : std::uint8_t {
    kIdle,
    kInitiateDownload,       ///< waiting for 60h
    kDownloadSegments,       ///< segment sent, waiting for 20h/30h
    kInitiateUpload,         ///< waiting for 4xh
    kUploadSegments,         ///< segment requested, waiting for it
    kBlockDownloadInitiate,  ///< waiting for A0h/A4h
    kBlockDownloadSubBlock,  ///< sub-block sent, waiting for A2h
    kBlockDownloadEnd,       ///< end sent, waiting for A1h
    kBlockUploadInitiate,    ///< waiting for C2h/C6h (or 4xh after a protocol switch)
    kBlockUploadSubBlock,    ///< receiving segments
    kBlockUploadEnd,         ///< last segment acknowledged, waiting for the end (C1h)
  };

  struct Transfer {
    State state = State::kIdle;
    std::uint8_t node_id = 0;
    std::uint16_t index = 0;
    std::uint8_t sub_index = 0;
    Bytes data;                         ///< download: the value; upload: received so far
    std::size_t offset = 0;             ///< download: first byte not yet confirmed
    std::optional<std::uint32_t> size;  ///< upload: size indicated by the server
    bool toggle = false;
    bool crc = false;
    bool last = false;              ///< the segment with the last byte was sent / received
    std::uint8_t blksize = 0;       ///< segments in the current sub-block
    std::uint8_t seqno = 0;         ///< block download: segments sent; upload: last in-order seqno
    SdoUploadCallback upload_done;  ///< exactly one of the two is set
    SdoDownloadCallback download_done;
  };

  // sdo_client.cpp: requests, dispatch, expedited and segmented
  bool Begin(std::uint8_t node_id, std::uint16_t index, std::uint8_t sub_index);
  void Dispatch(const sdo::Payload& response);
  void Send(const sdo::Payload& payload) { SendTo(transfer_.node_id, payload); }
  void SendTo(std::uint8_t node_id, const sdo::Payload& payload);
  void RestartTimeout();
  void Await(State state);  ///< sets the state and restarts the timeout
  void Complete(SdoAbort result, const sdo::Payload* last_frame = nullptr);
  void Fail(SdoAbort code);  ///< sends the abort frame and completes with `code`
  bool MultiplexerMatches(const sdo::Payload& response) const;
  void OnInitiateUploadResponse(const sdo::Payload& response);
  void OnUploadSegment(const sdo::Payload& response);
  void OnInitiateDownloadResponse(const sdo::Payload& response);
  void OnDownloadSegmentResponse(const sdo::Payload& response);
  void SendDownloadSegment();

  // sdo_client_block.cpp
  void OnBlockDownloadInitiateResponse(const sdo::Payload& response);
  void SendSubBlock();
  void OnBlockDownloadAck(const sdo::Payload& response);
  void OnBlockUploadInitiateResponse(const sdo::Payload& response);
  void OnBlockUploadSegment(const sdo::Payload& response);
  void AcknowledgeSubBlock();
  void OnSubBlockStalled();
  void OnBlockUploadEnd(const sdo::Payload& response);
  void RestartSubBlockTimer();

  BusPort& port_;
  SdoClientOptions options_;
  Timer timeout_;
  Timer sub_block_timer_;
  std::uint32_t generation_ = 0;  ///< bumped when a transfer ends or a sub-block starts
  Transfer transfer_;
};

}  // namespace canfleet::canopen
