#include "bus/socketcan/socketcan_socket.hpp"

#include <linux/can/raw.h>
#include <net/if.h>
#include <net/if_arp.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <asio/post.hpp>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>

#include "bus/socketcan/socketcan_codec.hpp"

namespace canfleet {
namespace {

std::string ErrorText(std::string_view interface, std::error_code code, std::string_view hint) {
  std::string text = "socketcan: ";
  text += interface;
  text += ": ";
  text += code.message();
  if (!hint.empty()) {
    text += " (";
    text += hint;
    text += ")";
  }
  return text;
}

std::error_code Errno(int value) {
  return {value, std::generic_category()};
}

[[noreturn]] void Throw(std::string_view interface, int error, std::string_view hint) {
  throw SocketCanError(interface, Errno(error), hint);
}

std::string CreateHint(std::string_view interface) {
  std::string hint = "no such network interface; a virtual one is made with `ip link add dev ";
  hint += interface;
  hint += " type vcan && ip link set up ";
  hint += interface;
  hint += "`";
  return hint;
}

void SetOption(int fd, std::string_view interface, int level, int name, const void* value, socklen_t size,
               std::string_view what) {
  if (::setsockopt(fd, level, name, value, size) != 0) Throw(interface, errno, what);
}

BusTime ReceiveTime(msghdr& header) {
  for (cmsghdr* c = CMSG_FIRSTHDR(&header); c != nullptr; c = CMSG_NXTHDR(&header, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
      timespec ts;
      std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
      return std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec);
    }
  }
  return BusTime{0};
}

bool WouldBlock(int error) {
  return error == EAGAIN || error == EWOULDBLOCK;
}

}  // namespace

SocketCanError::SocketCanError(std::string_view interface, std::error_code code, std::string_view hint)
    : std::runtime_error(ErrorText(interface, code, hint)), code_(code) {}

SocketCanSocket::SocketCanSocket(asio::io_context& io, std::string_view interface,
                                 const SocketCanOptions& options)
    : interface_(interface),
      descriptor_(io),
      retry_timer_(io),
      tx_ring_(std::max<std::size_t>(options.transmit_queue_frames, 1)) {
  if (interface.empty() || interface.size() >= IFNAMSIZ) {
    Throw(interface, EINVAL, "an interface name has 1 to 15 characters");
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    const int error = errno;
    switch (error) {
      case EAFNOSUPPORT:
        Throw(interface, error, "the kernel has no CAN support");
      case EPROTONOSUPPORT:
        Throw(interface, error, "the kernel's can-raw module is not loaded: modprobe can-raw");
      case EACCES:
      case EPERM:
        Throw(interface, error, "opening a raw CAN socket is not permitted here");
      default:
        Throw(interface, error, "cannot open a raw CAN socket");
    }
  }
  descriptor_.assign(fd);  // owns the descriptor from here on, even if we throw below

  ifreq request;
  std::memset(&request, 0, sizeof request);
  std::copy(interface.begin(), interface.end(), request.ifr_name);
  if (::ioctl(fd, SIOCGIFINDEX, &request) != 0) {
    const int error = errno;
    Throw(interface, error, error == ENODEV ? CreateHint(interface) : "cannot look the interface up");
  }
  const int index = request.ifr_ifindex;
  if (::ioctl(fd, SIOCGIFHWADDR, &request) != 0) Throw(interface, errno, "cannot read the interface type");
  if (request.ifr_hwaddr.sa_family != ARPHRD_CAN) Throw(interface, ENODEV, "not a CAN interface");
  if (::ioctl(fd, SIOCGIFFLAGS, &request) != 0) Throw(interface, errno, "cannot read the interface flags");
  if ((request.ifr_flags & IFF_UP) == 0) {
    Throw(interface, ENETDOWN, "the interface is down: ip link set up " + interface_);
  }

  const int loopback = options.loopback ? 1 : 0;
  const int own = options.receive_own_messages ? 1 : 0;
  const int on = 1;
  SetOption(fd, interface, SOL_CAN_RAW, CAN_RAW_LOOPBACK, &loopback, sizeof loopback, "CAN_RAW_LOOPBACK");
  SetOption(fd, interface, SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, &own, sizeof own, "CAN_RAW_RECV_OWN_MSGS");
  SetOption(fd, interface, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &options.error_mask, sizeof options.error_mask,
            "CAN_RAW_ERR_FILTER");
  if (options.receive_buffer_bytes > 0) {
    SetOption(fd, interface, SOL_SOCKET, SO_RCVBUF, &options.receive_buffer_bytes,
              sizeof options.receive_buffer_bytes, "SO_RCVBUF");
  }
  // Receive times are a convenience (captures, latency figures): a kernel without them is fine.
  (void)::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);

  sockaddr_can address;
  std::memset(&address, 0, sizeof address);
  address.can_family = AF_CAN;
  address.can_ifindex = index;
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const int error = errno;
    Throw(interface, error, error == ENODEV ? "not a CAN interface" : "cannot bind the CAN socket");
  }

  for (std::size_t i = 0; i < kBatch; ++i) {
    rx_iov_[i] = {&rx_kernel_[i], sizeof(can_frame)};
    tx_msgs_[i].msg_hdr.msg_iov = &tx_iov_[i];
    tx_msgs_[i].msg_hdr.msg_iovlen = 1;
  }
}

SocketCanSocket::~SocketCanSocket() {
  alive_.reset();  // pending handlers see this and return without touching the dead object
}

void SocketCanSocket::Start(BatchHandler on_batch, ErrorHandler on_error) {
  on_batch_ = std::move(on_batch);
  on_error_ = std::move(on_error);
  WaitReadable();
}

void SocketCanSocket::WaitReadable() {
  descriptor_.async_wait(asio::posix::descriptor_base::wait_read,
                         [this, alive = std::weak_ptr<int>(alive_)](const std::error_code& ec) {
                           if (alive.expired() || ec == asio::error::operation_aborted) return;
                           if (ec) {
                             ReportError(ec);
                             return;
                           }
                           ReadBatches();
                         });
}

void SocketCanSocket::ReadBatches() {
  const std::weak_ptr<int> alive = alive_;
  // A bounded number of batches per wake-up, so one busy interface cannot starve the io_context.
  for (int round = 0; round < 16; ++round) {
    for (std::size_t i = 0; i < kBatch; ++i) {
      msghdr& header = rx_msgs_[i].msg_hdr;
      header.msg_name = nullptr;
      header.msg_namelen = 0;
      header.msg_iov = &rx_iov_[i];
      header.msg_iovlen = 1;
      header.msg_control = rx_control_[i].bytes.data();
      header.msg_controllen = rx_control_[i].bytes.size();
      header.msg_flags = 0;
      rx_msgs_[i].msg_len = 0;
    }
    const int received =
        ::recvmmsg(descriptor_.native_handle(), rx_msgs_.data(), kBatch, MSG_DONTWAIT, nullptr);
    if (received < 0) {
      const int error = errno;
      if (error == EINTR) continue;
      if (WouldBlock(error)) break;
      // Socket errors (the interface went down, was deleted...) are reported once each by the
      // kernel; a descriptor that keeps failing is given up rather than spun on.
      if (++rx_error_streak_ > 1000) {
        ReportError(Errno(error));
        return;
      }
      ReportError(Errno(error));
      if (alive.expired()) return;
      break;
    }
    rx_error_streak_ = 0;
    if (received == 0) break;
    ++stats_.rx_batches;
    std::size_t count = 0;
    for (int i = 0; i < received; ++i) {
      auto& message = rx_msgs_[static_cast<std::size_t>(i)];
      std::optional<CanFrame> frame;
      if (message.msg_len == sizeof(can_frame) && (message.msg_hdr.msg_flags & MSG_TRUNC) == 0) {
        frame = FromKernelFrame(rx_kernel_[static_cast<std::size_t>(i)]);
      }
      if (!frame) {
        ++stats_.rx_malformed;
        continue;
      }
      ++(frame->error() ? stats_.rx_error_frames : stats_.rx_frames);
      rx_frames_[count] = *frame;
      rx_times_[count] = ReceiveTime(message.msg_hdr);
      ++count;
    }
    if (count > 0 && on_batch_) {
      on_batch_(std::span<const CanFrame>(rx_frames_.data(), count),
                std::span<const BusTime>(rx_times_.data(), count));
      if (alive.expired()) return;
    }
    if (static_cast<std::size_t>(received) < kBatch) break;
  }
  WaitReadable();
}

std::size_t SocketCanSocket::Send(std::span<const CanFrame> frames) {
  std::size_t queued = 0;
  for (const CanFrame& frame : frames) {
    if (!frame.valid() || tx_count_ == tx_ring_.size()) {
      ++stats_.tx_refused;
      continue;
    }
    tx_ring_[(tx_head_ + tx_count_) % tx_ring_.size()] = ToKernelFrame(frame);
    ++tx_count_;
    ++queued;
  }
  if (queued > 0) ScheduleFlush();
  return queued;
}

void SocketCanSocket::ScheduleFlush() {
  if (flush_scheduled_ || tx_blocked_) return;
  flush_scheduled_ = true;
  asio::post(descriptor_.get_executor(), [this, alive = std::weak_ptr<int>(alive_)] {
    if (alive.expired()) return;
    flush_scheduled_ = false;
    Flush();
  });
}

void SocketCanSocket::Flush() {
  while (tx_count_ > 0) {
    const std::size_t batch = std::min(tx_count_, kBatch);
    for (std::size_t i = 0; i < batch; ++i) {
      tx_iov_[i] = {&tx_ring_[(tx_head_ + i) % tx_ring_.size()], sizeof(can_frame)};
      tx_msgs_[i].msg_len = 0;
    }
    const int sent =
        ::sendmmsg(descriptor_.native_handle(), tx_msgs_.data(), static_cast<unsigned>(batch), MSG_DONTWAIT);
    if (sent > 0) {
      const auto n = static_cast<std::size_t>(sent);
      tx_head_ = (tx_head_ + n) % tx_ring_.size();
      tx_count_ -= n;
      stats_.tx_frames += n;
      ++stats_.tx_batches;
      continue;
    }
    const int error = sent < 0 ? errno : EAGAIN;
    if (error == EINTR) continue;
    if (WouldBlock(error)) {
      // The socket's send buffer is full: poll tells when there is room again.
      tx_blocked_ = true;
      descriptor_.async_wait(asio::posix::descriptor_base::wait_write,
                             [this, alive = std::weak_ptr<int>(alive_)](const std::error_code& ec) {
                               if (alive.expired() || ec == asio::error::operation_aborted) return;
                               tx_blocked_ = false;
                               Flush();
                             });
      return;
    }
    if (error == ENOBUFS) {
      // The interface's transmit queue is full (txqueuelen). poll() does not signal this
      // condition, so retry shortly instead of spinning on a "writable" socket.
      tx_blocked_ = true;
      retry_timer_.expires_after(std::chrono::milliseconds(1));
      retry_timer_.async_wait([this, alive = std::weak_ptr<int>(alive_)](const std::error_code& ec) {
        if (alive.expired() || ec == asio::error::operation_aborted) return;
        tx_blocked_ = false;
        Flush();
      });
      return;
    }
    // The kernel refuses these frames (interface down or gone): drop what is queued, as a CAN
    // driver drops its queue, and tell the owner. A later Send tries again.
    stats_.tx_failed += tx_count_;
    tx_head_ = 0;
    tx_count_ = 0;
    ReportError(Errno(error));
    return;
  }
}

void SocketCanSocket::ReportError(std::error_code code) {
  ++stats_.io_errors;
  if (on_error_) on_error_(code);
}

}  // namespace canfleet
