#pragma once
/// @file Non-blocking reads and writes on a connected stream socket, for the transport's hot
/// paths (the broker's sessions and the node's BrokerClientPort).
///
/// Why not Asio's async_read_some/async_write: each completes through a handler, and
/// async_read_some first tries a recv before waiting. Issued after every completed read, that
/// recv finds the socket drained: half of the broker's recv calls returned EAGAIN (perf trace,
/// bench/transport/README.md). With these calls a connection reads until a read comes back short,
/// then waits for readiness (socket.async_wait), and writes straight from the caller's buffers.

#include <sys/uio.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <system_error>

namespace canfleet::wire {

/// One recv of at most `into.size()` bytes that never blocks. Returns the bytes read (a short
/// count means the socket was drained at that moment). With nothing to read: 0 and WouldBlock(ec).
/// When the peer has closed its end: 0 and `ec` == EndOfStream(). Other failures: 0 and the
/// errno in `ec`.
std::size_t ReceiveNow(int fd, std::span<std::uint8_t> into, std::error_code& ec);

/// One sendmsg of `buffers`, in order, that never blocks and never raises SIGPIPE. Returns the
/// bytes the socket took (possibly fewer than offered). With no room at all: 0 and `ec` =
/// std::errc::operation_would_block. Failures: 0 and the errno in `ec`.
std::size_t SendNow(int fd, std::span<const iovec> buffers, std::error_code& ec);

/// The code ReceiveNow reports when the peer has closed its end.
const std::error_code& EndOfStream();

/// True for the "nothing to read / no room to write" result of ReceiveNow and SendNow.
inline bool WouldBlock(const std::error_code& ec) {
  return ec == std::errc::operation_would_block || ec == std::errc::resource_unavailable_try_again;
}

/// Bytes in `buffers`.
std::size_t TotalSize(std::span<const iovec> buffers);

/// Appends to `out` what SendNow left of `buffers` after taking `sent` bytes of them: the tail a
/// partial write must still carry. `out(data, size)` is called once per remaining piece.
template <class Append>
void AppendUnsent(std::span<const iovec> buffers, std::size_t sent, Append&& out) {
  for (const iovec& b : buffers) {
    if (sent >= b.iov_len) {
      sent -= b.iov_len;
      continue;
    }
    out(static_cast<const std::uint8_t*>(b.iov_base) + sent, b.iov_len - sent);
    sent = 0;
  }
}

}  // namespace canfleet::wire
