#pragma once
// The processes of the transport benchmark besides the driver. Each prints "ready" on stdout
// when it can start, waits for "go T0 T1 T2" on stdin (CLOCK_MONOTONIC ns: measure from T0 to T1,
// stop at T2), then prints one "result ..." line and exits.
//
// Traffic shape, the same for the broker and the raw relay:
// - throughput: every node sends 8-byte frames carrying their send time, at most `window` frames
//   ahead of its share of what it has received (sent <= received / (ports - 1) + window). All
//   nodes send at once, so the window keeps every queue bounded and nothing is dropped.
// - latency: node 0 sends one frame every 1/rate s; every other node measures send -> receive.
// Every node counts the frames it receives between T0 and T1 and records their latency.

#include <cstddef>
#include <cstdint>
#include <string>

namespace canfleet::bench {

struct ClientConfig {
  std::string endpoint;  ///< broker: tcp://... or unix://...; raw: unix://... of the relay
  int index = 0;         ///< 0..ports-1
  int ports = 2;
  std::size_t window = 128;
  bool latency = false;  ///< latency mode instead of throughput
  double rate = 2000;    ///< latency mode: frames/s sent by node 0
};

/// A node on canfleet-broker through BrokerClientPort.
int RunBrokerClient(const ClientConfig& config);
/// A node on the raw relay: a non-blocking Unix socket carrying bare 24-byte records.
int RunRawClient(const ClientConfig& config);
/// The raw relay: accepts `ports` connections on `path` and forwards each one's whole records to
/// all the others, one write per receiver per epoll round. The IPC limit of this machine for the
/// broker's traffic shape, with none of the broker's work.
/// `where`: a Unix socket path, or "tcp" (127.0.0.1, a port the kernel picks). Prints
/// "ready ENDPOINT" once listening.
int RunRelay(const std::string& where, int ports);

/// "go T0 T1 T2".
struct Window {
  std::int64_t start = 0;
  std::int64_t end = 0;
  std::int64_t stop = 0;
};
bool ParseGo(const std::string& line, Window& window);

/// Frame payload: the send time, little-endian.
void StoreTime(std::int64_t ns, std::uint8_t* data);
std::int64_t LoadTime(const std::uint8_t* data);

}  // namespace canfleet::bench
