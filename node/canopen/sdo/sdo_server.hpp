#pragma once
/// @file The SDO server of a CANopen slave (CiA 301 v4.2 §7.2.4): expedited, segmented and block
/// upload/download of object dictionary entries, with the SDO timeout and every abort code of
/// §7.2.4.3.17 where it applies.
///
/// The dispatcher and transfer state live in sdo_server.cpp; each protocol has its own file:
/// expedited.cpp (initiate download/upload, the expedited case), segmented.cpp,
/// block_download.cpp and block_upload.cpp. Frame layouts are in sdo_protocol.hpp.
///
/// Decisions where CiA 301 leaves a choice, with the implementation followed:
/// - Frames with DLC ≠ 8 and remote frames on the request COB-ID are ignored (CANopenNode
///   `CO_SDO_receive`: "ignore messages with wrong length"); OnFrame still returns true.
/// - An initiate request while a transfer is in progress starts the new transfer; the old one is
///   dropped without an abort frame (python-canopen `SdoServer.on_request` dispatches on the
///   command specifier alone). CANopenNode and Lely abort with 05040001 instead. During the
///   sub-blocks of a block download every frame but 80h is a segment (its byte 0 is c|seqno),
///   so there a new request is not recognised until the transfer ends or times out.
/// - Any other unexpected command specifier aborts with 05040001, also a segment when no
///   transfer is in progress; without a transfer the abort frame carries index 0000h sub 00h
///   (Lely `co_ssdo_abort_ind` clears the multiplexer).
/// - Downloads are buffered and written to the OD once, when complete, so a failed or aborted
///   transfer never leaves a partial value (CANopenNode writes in pieces; we can afford RAM).
/// - Block download: segments out of sequence are dropped and the sub-block is acknowledged with
///   the last in-order seqno when seqno = blksize or c = 1 arrives (Lely `co_ssdo_blk_dn_sub_on_recv`);
///   seqno 0 or above blksize aborts with 05040003 (Lely). If a sub-block stalls for 70 % of the
///   SDO timeout the server acknowledges what it has so the client resends (CANopenNode's
///   `block_SDOtimeoutTime_us`), which recovers a lost last segment.
/// - Block upload answers with a normal upload when pst > 0 and the size is ≤ pst
///   (§7.2.4.3.13; Lely `co_ssdo_blk_up_ini_on_recv`).

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "bus/bus_port.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/od/object_dictionary.hpp"
#include "node/canopen/sdo/sdo_protocol.hpp"

namespace canfleet::canopen {

struct SdoServerOptions {
  /// SDO timeout between two frames of the client in a transfer (CiA 301 leaves the value to the
  /// device; CANopenNode's examples use 1000 ms). On expiry the server sends abort 05040000.
  /// Zero or negative: no timeout.
  Duration timeout = std::chrono::seconds(1);
  /// Largest download the server buffers, in bytes; a larger indicated size, or more data without
  /// one, aborts with 05040005 (out of memory).
  std::size_t max_transfer_bytes = 1 << 20;
  /// Segments per sub-block the server proposes in a block download, 1..127 (others are clamped).
  std::uint8_t block_size = sdo::kMaxBlockSize;
};

/// Adds the SDO server parameter object 1200h (CiA 301 §7.5.2.33): RECORD, sub0 = 2 (U8 const),
/// sub1 = COB-ID client→server (U32 ro, $NODEID+600h), sub2 = COB-ID server→client (U32 ro,
/// $NODEID+580h). Replaces an existing 1200h.
void AddSdoServerObjects(ObjectDictionary& od);

/// One SDO server channel. Not thread-safe: used from the node's event loop. A new server is
/// enabled but deaf until SetNodeId() gives it a valid node-ID.
class SdoServer {
 public:
  /// @param od the dictionary served; must outlive the server (listeners on 1200h capture it).
  /// @param port where responses are sent. @param scheduler runs the SDO timeout.
  SdoServer(ObjectDictionary& od, BusPort& port, Scheduler& scheduler, SdoServerOptions options = {});
  SdoServer(const SdoServer&) = delete;
  SdoServer& operator=(const SdoServer&) = delete;

  /// Takes the COB-IDs for `node_id`: 600h+id (requests) and 580h+id (responses) by default; if
  /// the OD has 1200h, its sub1/sub2 defaults with the node-ID applied ($NODEID) are used and
  /// written back to sub1/sub2. A node-ID outside 1..127 (e.g. FFh, LSS-unconfigured) leaves the
  /// server deaf. A transfer in progress is aborted with 060A0023 on the old response COB-ID.
  /// 1200h sub1/sub2 writes by the device (or RestoreDefaults) are followed through a listener;
  /// bit 31 set = server invalid, bit 29 = 29-bit identifier.
  void SetNodeId(std::uint8_t node_id);

  /// The stack enables the server in pre-operational and operational only (CiA 301 §7.3.2.2,
  /// table 51). When disabled, frames are ignored (OnFrame returns false) and a transfer in
  /// progress is dropped silently.
  void SetEnabled(bool enabled);

  /// Handles one received frame. Returns true when the frame has this server's request COB-ID
  /// (and the server is enabled), whether or not it was a valid request.
  bool OnFrame(const CanFrame& frame);
  /// The 11-bit identifiers it listens to: its request COB-ID (whatever the NMT state: a request
  /// in stopped gets no answer, but it is heard).
  void AddListenedIds(std::vector<std::uint32_t>& ids) const;

  bool Enabled() const { return enabled_; }
  /// True while a segmented or block transfer is in progress.
  bool Busy() const { return transfer_.state != State::kIdle; }
  /// The COB-IDs in use, in the 1200h format (bit 31 set = not valid).
  std::uint32_t RequestCobId() const { return request_cob_id_; }
  std::uint32_t ResponseCobId() const { return response_cob_id_; }

 private:
  enum class State : std::uint8_t {
    kIdle,
    kDownloadSegments,       ///< §7.2.4.3.4: waiting for a download segment
    kUploadSegments,         ///< §7.2.4.3.7: waiting for an upload segment request
    kBlockDownloadSubBlock,  ///< §7.2.4.3.10: receiving segments
    kBlockDownloadEnd,       ///< §7.2.4.3.11: waiting for the end request
    kBlockUploadStart,       ///< §7.2.4.3.13: waiting for the start (A3h)
    kBlockUploadSubBlock,    ///< §7.2.4.3.14: sub-block sent, waiting for its acknowledgement
    kBlockUploadEnd,         ///< §7.2.4.3.15: end sent, waiting for the end response
  };

  /// Everything about the transfer in progress; reset to {} when it ends.
  struct Transfer {
    State state = State::kIdle;
    std::uint16_t index = 0;
    std::uint8_t sub_index = 0;
    Bytes data;                         ///< download: received so far; upload: the value read at initiate
    std::size_t offset = 0;             ///< upload: first byte not yet acknowledged
    std::optional<std::uint32_t> size;  ///< download: size indicated by the client
    bool toggle = false;                ///< segmented: toggle bit expected next
    bool crc = false;                   ///< block: both sides generate a CRC
    std::uint8_t blksize = 0;           ///< block: segments in the current sub-block
    std::uint8_t seqno = 0;             ///< block download: last in-order seqno; upload: segments sent
    bool last = false;                  ///< block: the segment with c = 1 was received / sent
  };

  // sdo_server.cpp: dispatch and shared state handling
  void Dispatch(const sdo::Payload& request);
  void Start(std::uint16_t index, std::uint8_t sub_index);  ///< drops any transfer, takes the new multiplexer
  void Enter(State state);                                  ///< continues the transfer in `state`
  void Finish();                                            ///< back to idle without a frame
  void Abort(SdoAbort code);  ///< Finish(), then the abort frame for the transfer's multiplexer
  void Send(const sdo::Payload& payload);
  void RestartTimeout();
  void RestartSubBlockTimer();
  void OnTimeout();
  void ApplyCobIds(std::uint32_t request, std::uint32_t response);
  void WatchParameterObject();
  void FollowParameterObject();
  SdoAbort CheckDownloadTarget(std::optional<std::uint32_t> size);
  void Commit(const sdo::Payload& response);

  // expedited.cpp
  void OnInitiateDownload(const sdo::Payload& request);
  void OnInitiateUpload(const sdo::Payload& request);
  void RespondToUpload();

  // segmented.cpp
  void StartSegmentedDownload(std::optional<std::uint32_t> size);
  void OnDownloadSegment(const sdo::Payload& request);
  void StartSegmentedUpload();
  void OnUploadSegmentRequest(const sdo::Payload& request);

  // block_download.cpp
  void OnBlockDownloadInitiate(const sdo::Payload& request);
  void OnBlockDownloadSegment(const sdo::Payload& request);
  void OnBlockDownloadEnd(const sdo::Payload& request);
  void AcknowledgeSubBlock();
  void OnSubBlockStalled();

  // block_upload.cpp
  void OnBlockUploadInitiate(const sdo::Payload& request);
  void OnBlockUploadStart();
  void OnBlockUploadAck(const sdo::Payload& request);
  void SendSubBlock();

  ObjectDictionary& od_;
  BusPort& port_;
  SdoServerOptions options_;
  Timer timeout_;
  Timer sub_block_timer_;
  SubObject* watched_[2] = {nullptr, nullptr};  ///< 1200h sub1/sub2 carrying our listener
  bool enabled_ = true;
  std::uint8_t node_id_ = 0;
  std::uint32_t request_cob_id_ = 0x80000000;  ///< bit 31: not valid
  std::uint32_t response_cob_id_ = 0x80000000;
  std::uint32_t generation_ = 0;  ///< bumped when a transfer ends or a sub-block starts: stops stale loops
  Transfer transfer_;
};

}  // namespace canfleet::canopen
