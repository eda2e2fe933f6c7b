#pragma once
/// @file One AF_CAN raw socket bound to an interface, driven by an Asio io_context: batched
/// receive (recvmmsg) and batched transmit (sendmmsg) through fixed buffers, so no frame costs an
/// allocation. SocketCanPort and SocketCanBridge are built on it.

#include <linux/can.h>
#include <linux/can/error.h>
#include <sys/socket.h>

#include <array>
#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>
#include <asio/steady_timer.hpp>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "bus/bus_port.hpp"
#include "bus/can_frame.hpp"

namespace canfleet {

/// Opening a SocketCAN interface failed. what() reads like
/// "socketcan: vcan0: Address family not supported by protocol (the kernel has no CAN support)".
class SocketCanError : public std::runtime_error {
 public:
  SocketCanError(std::string_view interface, std::error_code code, std::string_view hint);
  std::error_code code() const { return code_; }

 private:
  std::error_code code_;
};

/// How a raw socket is set up (linux/can/raw.h socket options).
struct SocketCanOptions {
  /// The error classes that announce a controller state change (see socketcan_codec.hpp).
  static constexpr can_err_mask_t kStateErrorClasses = CAN_ERR_CRTL | CAN_ERR_BUSOFF | CAN_ERR_RESTARTED;

  /// CAN_RAW_LOOPBACK: other sockets on this host bound to the same interface (candump, other
  /// nodes on vcan0) see the frames we send. On a virtual interface this is the only way they see
  /// them, so it stays on unless you know why.
  bool loopback = true;
  /// CAN_RAW_RECV_OWN_MSGS: receive our own transmitted frames back. Off: a port never hears
  /// itself, as on a real controller, and a bridge never re-forwards what it wrote.
  bool receive_own_messages = false;
  /// CAN_RAW_ERR_FILTER: the error classes (linux/can/error.h CAN_ERR_*) to receive. The default
  /// covers the classes that announce a controller state change.
  can_err_mask_t error_mask = kStateErrorClasses;
  /// Frames waiting for the kernel (sendmmsg batches); a Send beyond this is refused.
  std::size_t transmit_queue_frames = 1024;
  /// SO_RCVBUF in bytes; 0 keeps the kernel's default. Raise it for bursts from a busy bus.
  int receive_buffer_bytes = 0;
};

/// Counters for diagnostics and tests.
struct SocketCanStats {
  std::uint64_t rx_frames = 0;        ///< data/remote frames received
  std::uint64_t rx_error_frames = 0;  ///< error frames received
  std::uint64_t rx_malformed = 0;     ///< not a classical CAN frame (dropped)
  std::uint64_t rx_batches = 0;       ///< recvmmsg calls that returned frames
  std::uint64_t tx_frames = 0;        ///< frames the kernel accepted
  std::uint64_t tx_batches = 0;       ///< sendmmsg calls that sent frames
  std::uint64_t tx_refused = 0;       ///< invalid frames or full queue: Send returned false
  std::uint64_t tx_failed = 0;        ///< frames the kernel rejected (interface down, ...)
  std::uint64_t io_errors = 0;        ///< socket errors reported through the error handler
};

/// A raw CAN socket on an io_context. All callbacks run on the thread that runs the io_context.
/// A callback may destroy the socket.
class SocketCanSocket {
 public:
  /// A batch of received frames and their kernel receive times (SO_TIMESTAMPNS, nanoseconds since
  /// the Unix epoch; 0 if the kernel gave none). Error frames are included, with kError set.
  using BatchHandler = std::function<void(std::span<const CanFrame>, std::span<const BusTime>)>;
  /// A socket error (interface went down or disappeared, ...). The socket keeps going.
  using ErrorHandler = std::function<void(std::error_code)>;

  /// Opens and binds the socket. Throws SocketCanError with a clear reason (no CAN in the kernel,
  /// no such interface, not a CAN interface, interface down, no permission).
  SocketCanSocket(asio::io_context& io, std::string_view interface, const SocketCanOptions& options);
  ~SocketCanSocket();
  SocketCanSocket(const SocketCanSocket&) = delete;
  SocketCanSocket& operator=(const SocketCanSocket&) = delete;

  /// Starts receiving. Handlers are kept for the socket's lifetime.
  void Start(BatchHandler on_batch, ErrorHandler on_error);

  /// Queues frames for transmission; they are handed to the kernel in sendmmsg batches from the
  /// io_context (the first Send of a turn posts one flush). Returns how many were queued, in order;
  /// the rest (invalid frames, or a full queue) are refused and counted in tx_refused.
  std::size_t Send(std::span<const CanFrame> frames);
  bool Send(const CanFrame& frame) { return Send(std::span<const CanFrame>(&frame, 1)) == 1; }

  const std::string& Interface() const { return interface_; }
  const SocketCanStats& Stats() const { return stats_; }
  /// Frames queued and not yet accepted by the kernel.
  std::size_t Pending() const { return tx_count_; }

  /// Most frames handed to the batch handler at once (one recvmmsg).
  static constexpr std::size_t kBatch = 64;

 private:
  static constexpr std::size_t kControlBytes = 64;  // room for one SCM_TIMESTAMPNS cmsg

  void WaitReadable();
  void ReadBatches();
  void ScheduleFlush();
  void Flush();
  void ReportError(std::error_code code);

  std::string interface_;
  asio::posix::stream_descriptor descriptor_;
  asio::steady_timer retry_timer_;
  BatchHandler on_batch_;
  ErrorHandler on_error_;
  SocketCanStats stats_;
  /// Expires when the socket is destroyed: pending handlers and a callback that destroyed us
  /// check it before touching members.
  std::shared_ptr<int> alive_ = std::make_shared<int>(0);

  // Receive buffers, reused for every batch.
  struct alignas(cmsghdr) Control {
    std::array<unsigned char, kControlBytes> bytes;
  };
  std::array<can_frame, kBatch> rx_kernel_{};
  std::array<iovec, kBatch> rx_iov_{};
  std::array<Control, kBatch> rx_control_{};
  std::array<mmsghdr, kBatch> rx_msgs_{};
  std::array<CanFrame, kBatch> rx_frames_{};
  std::array<BusTime, kBatch> rx_times_{};

  // Transmit ring of kernel frames, fixed capacity.
  std::vector<can_frame> tx_ring_;
  std::size_t tx_head_ = 0;
  std::size_t tx_count_ = 0;
  bool flush_scheduled_ = false;  // a Flush is posted
  bool tx_blocked_ = false;       // waiting for writability or the ENOBUFS retry timer
  unsigned rx_error_streak_ = 0;  // receive errors without a frame in between
  std::array<iovec, kBatch> tx_iov_{};
  std::array<mmsghdr, kBatch> tx_msgs_{};
};

}  // namespace canfleet
