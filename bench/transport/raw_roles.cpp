// The raw baseline: a relay that forwards bare records between Unix (or TCP) sockets, and its nodes.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "bench/transport/bench_process.hpp"
#include "bench/transport/latency_histogram.hpp"
#include "bench/transport/roles.hpp"
#include "bus/wire/endpoint.hpp"
#include "bus/wire/frame_record.hpp"

namespace canfleet::bench {

namespace {

constexpr std::size_t kRecord = wire::kFrameRecordSize;

sockaddr_un UnixAddress(const std::string& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof(addr.sun_path) - 1);
  return addr;
}

void NoDelay(int fd) {
  const int on = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
}

void SetNonBlocking(int fd) {
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
}

/// Writes as much of `out` as the socket takes; keeps the rest.
bool WriteSome(int fd, std::vector<std::uint8_t>& out) {
  if (out.empty()) return true;
  const ssize_t n = ::send(fd, out.data(), out.size(), MSG_NOSIGNAL);
  if (n < 0) return errno == EAGAIN || errno == EINTR;
  out.erase(out.begin(), out.begin() + n);
  return true;
}

}  // namespace

int RunRelay(const std::string& where, int ports) {
  // `where`: a Unix socket path, or "tcp" for a TCP listener on 127.0.0.1 (port chosen by the
  // kernel, printed after "ready").
  const bool tcp = where == "tcp";
  int listener = -1;
  std::string ready = "ready";
  if (tcp) {
    listener = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof addr;
    if (::bind(listener, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0 ||
        ::listen(listener, 64) != 0 ||
        ::getsockname(listener, reinterpret_cast<sockaddr*>(&addr), &length) != 0) {
      std::perror("relay: bind/listen");
      return 1;
    }
    ready += " tcp://127.0.0.1:" + std::to_string(ntohs(addr.sin_port));
  } else {
    ::unlink(where.c_str());
    listener = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const sockaddr_un addr = UnixAddress(where);
    if (::bind(listener, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0 ||
        ::listen(listener, 64) != 0) {
      std::perror("relay: bind/listen");
      return 1;
    }
    ready += " unix://" + where;
  }
  std::printf("%s\n", ready.c_str());
  std::fflush(stdout);

  struct Peer {
    int fd;
    std::vector<std::uint8_t> partial;  // received bytes not yet a whole record
    std::vector<std::uint8_t> out;      // records waiting for this peer
  };
  std::vector<Peer> peers;
  while (static_cast<int>(peers.size()) < ports) {
    const int fd = ::accept4(listener, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (fd < 0) continue;
    if (tcp) NoDelay(fd);  // as the broker: a batch is whole when written
    peers.push_back({fd, {}, {}});
  }
  const int ep = ::epoll_create1(EPOLL_CLOEXEC);
  for (std::size_t i = 0; i < peers.size(); ++i) {
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.u64 = i;
    ::epoll_ctl(ep, EPOLL_CTL_ADD, peers[i].fd, &ev);
    peers[i].partial.reserve(1 << 18);
    peers[i].out.reserve(1 << 20);
  }
  std::vector<std::uint8_t> buf(1 << 18);
  std::vector<bool> want_out(peers.size(), false);
  std::size_t open = peers.size();
  epoll_event events[64];
  while (open > 0) {
    const int n = ::epoll_wait(ep, events, 64, 1000);
    for (int e = 0; e < n; ++e) {
      const std::size_t i = events[e].data.u64;
      Peer& p = peers[i];
      if (events[e].events & (EPOLLIN | EPOLLHUP | EPOLLERR)) {
        const ssize_t got = ::recv(p.fd, buf.data(), buf.size(), 0);
        if (got == 0 || (got < 0 && errno != EAGAIN && errno != EINTR)) {
          ::epoll_ctl(ep, EPOLL_CTL_DEL, p.fd, nullptr);
          ::close(p.fd);
          p.fd = -1;
          --open;
          continue;
        }
        if (got > 0) {
          p.partial.insert(p.partial.end(), buf.begin(), buf.begin() + got);
          const std::size_t whole = p.partial.size() / kRecord * kRecord;
          for (std::size_t j = 0; j < peers.size(); ++j)
            if (j != i && peers[j].fd >= 0)
              peers[j].out.insert(peers[j].out.end(), p.partial.begin(),
                                  p.partial.begin() + static_cast<std::ptrdiff_t>(whole));
          p.partial.erase(p.partial.begin(), p.partial.begin() + static_cast<std::ptrdiff_t>(whole));
        }
      }
    }
    // One write per receiver per round, as the broker does.
    for (std::size_t j = 0; j < peers.size(); ++j) {
      Peer& p = peers[j];
      if (p.fd < 0) continue;
      WriteSome(p.fd, p.out);
      const bool pending = !p.out.empty();
      if (pending != want_out[j]) {
        epoll_event ev{};
        ev.events = EPOLLIN | (pending ? EPOLLOUT : 0u);
        ev.data.u64 = j;
        ::epoll_ctl(ep, EPOLL_CTL_MOD, p.fd, &ev);
        want_out[j] = pending;
      }
    }
  }
  if (!tcp) ::unlink(where.c_str());
  return 0;
}

int RunRawClient(const ClientConfig& c) {
  const wire::Endpoint endpoint = wire::Endpoint::Parse(c.endpoint);
  int fd = -1;
  if (endpoint.kind == wire::Endpoint::Kind::kTcp) {
    fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(endpoint.port);
    ::inet_pton(AF_INET, endpoint.host.c_str(), &addr.sin_addr);
    while (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    NoDelay(fd);
  } else {
    fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const sockaddr_un addr = UnixAddress(endpoint.path);
    while (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  SetNonBlocking(fd);
  std::printf("ready\n");
  std::fflush(stdout);
  std::string line;
  std::getline(std::cin, line);
  Window window;
  if (!ParseGo(line, window)) return 1;

  const auto id = static_cast<std::uint32_t>(0x100 + c.index);
  const std::uint64_t others = static_cast<std::uint64_t>(c.ports - 1);
  std::uint64_t received = 0;
  std::uint64_t in_window = 0;
  std::uint64_t sent = 0;
  LatencyHistogram histogram;
  std::vector<std::uint8_t> in(1 << 18);
  std::size_t have = 0;
  std::vector<std::uint8_t> out;
  out.reserve(1 << 20);
  const auto interval = static_cast<std::int64_t>(1e9 / c.rate);
  std::int64_t next_tick = MonotonicNs();
  auto append = [&] {
    CanFrame f;
    f.id = id;
    f.dlc = 8;
    StoreTime(MonotonicNs(), f.data.data());
    const std::size_t at = out.size();
    out.resize(at + kRecord);
    wire::EncodeRecord(f, BusTime::zero(), out.data() + at);
    ++sent;
  };
  for (;;) {
    const std::int64_t now = MonotonicNs();
    if (now >= window.stop) break;
    if (c.latency) {
      if (c.index == 0 && now >= next_tick) {
        append();
        next_tick += interval;
      }
    } else {
      const std::uint64_t allowed = received / others + c.window;
      while (sent < allowed)
        append();
    }
    if (!WriteSome(fd, out)) break;
    std::int64_t wait_ns = window.stop - now;
    if (c.latency && c.index == 0) wait_ns = std::min(wait_ns, next_tick - now);
    pollfd p{fd, static_cast<short>(POLLIN | (out.empty() ? 0 : POLLOUT)), 0};
    wait_ns = std::max<std::int64_t>(0, wait_ns);
    const timespec timeout{static_cast<time_t>(wait_ns / 1'000'000'000),
                           static_cast<long>(wait_ns % 1'000'000'000)};
    ::ppoll(&p, 1, &timeout, nullptr);
    if (!(p.revents & POLLIN)) continue;
    const ssize_t n = ::recv(fd, in.data() + have, in.size() - have, 0);
    if (n == 0) break;
    if (n < 0) continue;
    have += static_cast<std::size_t>(n);
    const std::int64_t at = MonotonicNs();
    std::size_t off = 0;
    for (; off + kRecord <= have; off += kRecord) {
      ++received;
      if (at >= window.start && at < window.end) {
        ++in_window;
        histogram.Add(at - LoadTime(in.data() + off + 16));
      }
    }
    std::memmove(in.data(), in.data() + off, have - off);
    have -= off;
  }
  std::printf("result rx=%llu sent=%llu kicks=0 writes=0 hist=%s\n",
              static_cast<unsigned long long>(in_window), static_cast<unsigned long long>(sent),
              histogram.Serialize().c_str());
  std::fflush(stdout);
  ::close(fd);
  return 0;
}

}  // namespace canfleet::bench
