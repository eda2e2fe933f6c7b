#include "bus/wire/socket_io.hpp"

#include <sys/socket.h>

#include <cerrno>
#include <climits>

namespace canfleet::wire {

namespace {

/// "end of stream": the peer closed its end (a recv of 0 bytes).
class EndOfStreamCategory final : public std::error_category {
 public:
  const char* name() const noexcept override { return "canfleet.stream"; }
  std::string message(int) const override { return "end of stream"; }
};

}  // namespace

const std::error_code& EndOfStream() {
  static const EndOfStreamCategory category;
  static const std::error_code code(1, category);
  return code;
}

std::size_t ReceiveNow(int fd, std::span<std::uint8_t> into, std::error_code& ec) {
  for (;;) {
    const ssize_t n = ::recv(fd, into.data(), into.size(), MSG_DONTWAIT);
    if (n > 0) {
      ec.clear();
      return static_cast<std::size_t>(n);
    }
    if (n == 0) {
      ec = into.empty() ? std::error_code() : EndOfStream();
      return 0;
    }
    if (errno == EINTR) continue;
    ec.assign(errno, std::system_category());
    return 0;
  }
}

std::size_t SendNow(int fd, std::span<const iovec> buffers, std::error_code& ec) {
  msghdr message{};
  message.msg_iov = const_cast<iovec*>(buffers.data());  // sendmsg does not write through it
  message.msg_iovlen = buffers.size() < IOV_MAX ? buffers.size() : IOV_MAX;
  for (;;) {
    const ssize_t n = ::sendmsg(fd, &message, MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n >= 0) {
      ec.clear();
      return static_cast<std::size_t>(n);
    }
    if (errno == EINTR) continue;
    ec.assign(errno, std::system_category());
    return 0;
  }
}

std::size_t TotalSize(std::span<const iovec> buffers) {
  std::size_t total = 0;
  for (const iovec& b : buffers)
    total += b.iov_len;
  return total;
}

}  // namespace canfleet::wire
