#include "bench/transport/roles.hpp"

#include <unistd.h>

#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>
#include <asio/post.hpp>
#include <asio/read_until.hpp>
#include <asio/steady_timer.hpp>
#include <asio/streambuf.hpp>
#include <cstdio>
#include <cstring>
#include <istream>
#include <sstream>

#include "bench/transport/bench_process.hpp"
#include "bench/transport/latency_histogram.hpp"
#include "bus/broker_client/broker_client_port.hpp"

namespace canfleet::bench {

namespace {

std::chrono::steady_clock::time_point At(std::int64_t ns) {
  return std::chrono::steady_clock::time_point(std::chrono::nanoseconds(ns));
}

}  // namespace

bool ParseGo(const std::string& line, Window& window) {
  std::istringstream in(line);
  std::string verb;
  in >> verb >> window.start >> window.end >> window.stop;
  return verb == "go" && !in.fail();
}

void StoreTime(std::int64_t ns, std::uint8_t* data) {
  std::memcpy(data, &ns, sizeof ns);
}

std::int64_t LoadTime(const std::uint8_t* data) {
  std::int64_t ns = 0;
  std::memcpy(&ns, data, sizeof ns);
  return ns;
}

int RunBrokerClient(const ClientConfig& c) {
  asio::io_context io(1);
  BrokerClientOptions options;
  options.endpoint = c.endpoint;
  options.bus = "can0";
  options.node_name = "bench" + std::to_string(c.index);
  options.initial_backoff = std::chrono::milliseconds(10);
  BrokerClientPort port(io, options);

  Window window;
  bool going = false;
  std::uint64_t received = 0;
  std::uint64_t in_window = 0;
  std::uint64_t sent = 0;
  std::uint64_t extra = 0;  // stall recovery: budget added by the kick timer
  std::uint64_t kicks = 0;
  LatencyHistogram histogram;
  const auto id = static_cast<std::uint32_t>(0x100 + c.index);
  const std::uint64_t others = static_cast<std::uint64_t>(c.ports - 1);

  auto send_one = [&] {
    CanFrame f;
    f.id = id;
    f.dlc = 8;
    StoreTime(MonotonicNs(), f.data.data());
    return port.Send(f);
  };
  auto pump = [&] {
    const std::uint64_t allowed = port.Stats().rx_frames / others + c.window + extra;
    while (sent < allowed) {
      if (!send_one()) break;
      ++sent;
    }
  };
  // Per frame this node does what the raw node does per record (count it, and record its latency
  // inside the measurement window); the rest is done once per socket read, as the raw node does
  // it once per recv: read the clock, decide whether the read is inside the window, and send what
  // the window allows (the port writes it in one write when the read's frames are delivered).
  const BrokerClientStats& port_stats = port.Stats();  // stays valid while the port lives
  std::uint64_t seen_reads = 0;
  std::int64_t turn_now = 0;
  bool turn_in_window = false;
  port.OnReceive([&](const CanFrame& f, BusTime) {
    if (port_stats.reads != seen_reads) {
      seen_reads = port_stats.reads;
      turn_now = MonotonicNs();
      turn_in_window = turn_now >= window.start && turn_now < window.end;
      if (going && !c.latency && turn_now < window.stop) pump();
    }
    ++received;
    if (turn_in_window) {
      ++in_window;
      histogram.Add(turn_now - LoadTime(f.data.data()));
    }
  });

  asio::posix::stream_descriptor input(io, ::dup(STDIN_FILENO));
  asio::streambuf line_buffer;
  asio::steady_timer kick(io);
  asio::steady_timer tick(io);
  asio::steady_timer end(io);
  std::uint64_t last_sent = 0;
  std::int64_t next_tick = 0;
  const auto interval = static_cast<std::int64_t>(1e9 / c.rate);

  std::function<void()> arm_kick = [&] {
    kick.expires_after(std::chrono::milliseconds(200));
    kick.async_wait([&](const asio::error_code& ec) {
      if (ec) return;
      if (sent == last_sent && MonotonicNs() < window.stop) {
        extra += c.window / 4 + 1;
        ++kicks;
        pump();
      }
      last_sent = sent;
      arm_kick();
    });
  };
  std::function<void()> arm_tick = [&] {
    next_tick += interval;
    tick.expires_at(At(next_tick));
    tick.async_wait([&](const asio::error_code& ec) {
      if (ec || MonotonicNs() >= window.stop) return;
      if (send_one()) ++sent;
      arm_tick();
    });
  };

  port.OnConnection([&](bool connected, const std::string&) {
    if (!connected || going) return;
    std::printf("ready\n");
    std::fflush(stdout);
    asio::async_read_until(input, line_buffer, '\n', [&](const asio::error_code& ec, std::size_t) {
      if (ec) return io.stop();
      std::istream in(&line_buffer);
      std::string line;
      std::getline(in, line);
      if (!ParseGo(line, window)) return io.stop();
      going = true;
      if (c.latency) {
        if (c.index == 0) {
          next_tick = MonotonicNs();
          arm_tick();
        }
      } else {
        pump();
        arm_kick();
      }
      end.expires_at(At(window.stop));
      end.async_wait([&](const asio::error_code&) {
        std::printf("result rx=%llu sent=%llu kicks=%llu writes=%llu hist=%s\n",
                    static_cast<unsigned long long>(in_window), static_cast<unsigned long long>(sent),
                    static_cast<unsigned long long>(kicks),
                    static_cast<unsigned long long>(port.Stats().writes), histogram.Serialize().c_str());
        std::fflush(stdout);
        io.stop();
      });
    });
  });
  io.run();
  return 0;
}

}  // namespace canfleet::bench
