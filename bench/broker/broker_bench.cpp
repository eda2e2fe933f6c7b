// In-process broker benchmark (issue 4, "Benchmark"): prints a table, it is not a test.
//
//   1. Unpaced deliveries/s for 2, 8 and 32 ports: every port submits a batch per round and
//      receives everyone else's (a frame to 31 ports is 31 deliveries). Two drivers: simulated
//      time (the broker alone) and AsioScheduler (broker + a real event loop, one timer per round).
//   2. Unpaced Submit→Deliver latency, in process, on the AsioScheduler: one port sends, the
//      others receive; the next frame is sent from the last receiver's callback.
//   3. Paced, 100 % offered load at 125 kbit/s and 1 Mbit/s: achieved vs theoretical frames/s and
//      loss, on simulated time (10 s of bus time) and in real time (AsioScheduler, 2 s).
//
// The cross-process figures (TCP/Unix transport, raw socket baseline, python-can) come with the
// transport. Usage: canfleet_broker_bench [seconds per measurement, default 1].

// First, before any standard header: Asio decides whether to use aligned_alloc from a libstdc++
// macro that only exists once a standard header was included, and clock/asio_scheduler.cpp
// includes Asio first. Both translation units must make the same choice (else allocation with
// operator new and release with free: an ODR mismatch AddressSanitizer reports).
#include "clock/asio_scheduler.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <asio/io_context.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "bus/physics/frame_timing.hpp"
#include "bus/wire/message_writer.hpp"
#include "clock/scheduler.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/transport/round_encoding.hpp"

namespace canfleet::broker {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

double Seconds(Clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

double CpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto tv = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6;
  };
  return tv(usage.ru_utime) + tv(usage.ru_stime);
}

CanFrame EightBytes(std::uint32_t id, std::uint8_t seed) {
  return CanFrame::Data(id, {seed, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77});
}

// ---------------------------------------------------------------------------------------------
// 1. Unpaced throughput

/// Counts deliveries; one designated port (the "pump") submits the next batch for every port when
/// its own batch is confirmed, so the Asio run is a closed loop with one timer per round.
/// With `encode`, it also does a TCP/Unix session's work per round: the frames go into a
/// wire::MessageWriter as transport::detail::NodeSession puts them (copies of the round's records,
/// encoded once for all sessions), closed into a message, then dropped.
class CountingSink : public PortSink {
 public:
  void Deliver(std::span<const TimedFrame> frames) override {
    deliveries += frames.size();
    if (!encode) return;
    writer.AddFrames(wire::MessageType::kFrames, frames, [](const TimedFrame& f) {
      return wire::StampedFrame{f.frame, f.time};
    });
    Send();
  }
  /// With `encode`: what transport::detail::NodeSession does, copies of one encoding of the round.
  /// Without: the default (Deliver), as for a sink that only implements Deliver.
  void DeliverShared(const SharedRound& round, std::span<const FrameRun> runs) override {
    if (!encode) {
      PortSink::DeliverShared(round, runs);
      return;
    }
    const std::uint8_t* records = transport::SharedRecords(round);
    std::size_t frames = 0;
    for (const FrameRun& run : runs)
      frames += run.size();
    writer.ExpectFrames(wire::MessageType::kFrames, frames);
    for (const FrameRun& run : runs) {
      writer.AddRecords(wire::MessageType::kFrames, records + std::size_t{run.begin} * wire::kFrameRecordSize,
                        run.size());
      deliveries += run.size();
    }
    Send();
  }
  void ControllerChanged(const ControllerEvent&) override {}
  void TxConfirmed(std::span<const TimedFrame> frames) override {
    if (on_confirm) on_confirm(frames.size());
  }
  /// What a session's write would send: closes the message, then forgets it.
  void Send() {
    bytes += writer.Bytes().size();
    writer.Clear();
  }
  std::uint64_t deliveries = 0;
  std::uint64_t bytes = 0;
  bool encode = false;
  wire::MessageWriter writer;
  std::function<void(std::size_t)> on_confirm;
};

struct UnpacedFleet {
  UnpacedFleet(Scheduler& scheduler, int ports, std::size_t batch, bool encode = false)
      : broker(scheduler), batch_size(batch) {
    broker.AddBus({.name = "bench", .paced = false, .tx_queue_capacity = 4 * batch});
    for (int i = 0; i < ports; ++i) {
      sinks.push_back(std::make_unique<CountingSink>());
      sinks.back()->encode = encode;
      ids.push_back(broker.Attach("bench", "p" + std::to_string(i), *sinks.back()));
      std::vector<CanFrame> frames;
      for (std::size_t k = 0; k < batch; ++k)
        frames.push_back(EightBytes(0x100 + static_cast<std::uint32_t>(i), static_cast<std::uint8_t>(k)));
      batches.push_back(std::move(frames));
    }
  }
  void SubmitRound() {
    for (std::size_t i = 0; i < ids.size(); ++i)
      broker.Submit(ids[i], batches[i]);
  }
  std::uint64_t Deliveries() const {
    std::uint64_t n = 0;
    for (const auto& s : sinks)
      n += s->deliveries;
    return n;
  }

  Broker broker;
  std::size_t batch_size;
  std::vector<std::unique_ptr<CountingSink>> sinks;
  std::vector<PortId> ids;
  std::vector<std::vector<CanFrame>> batches;
};

struct Throughput {
  double deliveries_per_s = 0;
  double frames_per_s = 0;
  double cpu_share = 0;  ///< CPU seconds / wall seconds (1.0 = one core busy)
};

std::size_t BatchFor(int ports) {
  return ports >= 32 ? 16 : 64;
}

Throughput UnpacedSimulated(int ports, double seconds, bool encode) {
  SimulatedScheduler s;
  const std::size_t batch = BatchFor(ports);
  UnpacedFleet fleet(s, ports, batch, encode);
  std::uint64_t rounds = 0;
  const double cpu0 = CpuSeconds();
  const auto t0 = Clock::now();
  const auto deadline = t0 + std::chrono::duration<double>(seconds);
  while (Clock::now() < deadline) {
    for (int k = 0; k < 64; ++k) {
      fleet.SubmitRound();
      s.Advance(1ns);
      ++rounds;
    }
  }
  const double wall = Seconds(Clock::now() - t0);
  Throughput out;
  out.deliveries_per_s = static_cast<double>(fleet.Deliveries()) / wall;
  out.frames_per_s = static_cast<double>(rounds * batch * static_cast<std::uint64_t>(ports)) / wall;
  out.cpu_share = (CpuSeconds() - cpu0) / wall;
  return out;
}

Throughput UnpacedAsio(int ports, double seconds) {
  asio::io_context io;
  AsioScheduler s(io);
  const std::size_t batch = BatchFor(ports);
  UnpacedFleet fleet(s, ports, batch);
  std::uint64_t rounds = 0;
  // The first port's confirmation of its batch arrives once per round: submit the next round
  // from there (it runs in the next turn of the event loop).
  fleet.sinks[0]->on_confirm = [&](std::size_t) {
    ++rounds;
    fleet.SubmitRound();
  };
  fleet.SubmitRound();
  const double cpu0 = CpuSeconds();
  const auto t0 = Clock::now();
  io.run_for(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds)));
  const double wall = Seconds(Clock::now() - t0);
  Throughput out;
  out.deliveries_per_s = static_cast<double>(fleet.Deliveries()) / wall;
  out.frames_per_s = static_cast<double>(rounds * batch * static_cast<std::uint64_t>(ports)) / wall;
  out.cpu_share = (CpuSeconds() - cpu0) / wall;
  return out;
}

// ---------------------------------------------------------------------------------------------
// 2. Unpaced latency

struct Latency {
  double p50_us = 0;
  double p99_us = 0;
  std::size_t samples = 0;
};

class LatencySink : public PortSink {
 public:
  void Deliver(std::span<const TimedFrame> frames) override {
    const auto now = Clock::now();
    for (std::size_t i = 0; i < frames.size(); ++i)
      samples->push_back(std::chrono::duration<double, std::micro>(now - *sent_at).count());
    if (on_deliver) on_deliver();
  }
  void ControllerChanged(const ControllerEvent&) override {}
  std::vector<double>* samples = nullptr;
  const Clock::time_point* sent_at = nullptr;
  std::function<void()> on_deliver;
};

Latency UnpacedLatency(int ports, std::size_t count) {
  asio::io_context io;
  AsioScheduler s(io);
  Broker broker(s);
  broker.AddBus({.name = "bench", .paced = false});
  std::vector<double> samples;
  samples.reserve(count * static_cast<std::size_t>(ports));
  Clock::time_point sent_at;
  std::vector<std::unique_ptr<LatencySink>> sinks;
  std::vector<PortId> ids;
  for (int i = 0; i < ports; ++i) {
    sinks.push_back(std::make_unique<LatencySink>());
    sinks.back()->samples = &samples;
    sinks.back()->sent_at = &sent_at;
    ids.push_back(broker.Attach("bench", "p" + std::to_string(i), *sinks.back()));
  }
  std::size_t sent = 0;
  auto send = [&] {
    if (sent++ == count) {
      io.stop();
      return;
    }
    sent_at = Clock::now();
    broker.Submit(ids[0], EightBytes(0x181, static_cast<std::uint8_t>(sent)));
  };
  sinks.back()->on_deliver = send;  // the last receiver triggers the next frame
  send();
  io.run();
  std::sort(samples.begin(), samples.end());
  Latency out;
  out.samples = samples.size();
  if (!samples.empty()) {
    out.p50_us = samples[samples.size() / 2];
    out.p99_us = samples[std::min(samples.size() - 1, samples.size() * 99 / 100)];
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// 3. Paced, 100 % offered load

/// Keeps `depth` frames queued on its port: every confirmed frame is replaced at once.
class Saturator : public PortSink {
 public:
  Saturator(Broker& broker, CanFrame frame) : broker_(broker), frame_(frame) {}
  void Start(PortId id, std::size_t depth) {
    id_ = id;
    for (std::size_t i = 0; i < depth; ++i)
      submitted += broker_.Submit(id_, frame_);
  }
  void Deliver(std::span<const TimedFrame> frames) override {
    if (frames.empty()) return;
    if (received == 0) first_time = frames.front().time;
    received += frames.size();
    last_time = frames.back().time;
  }
  void ControllerChanged(const ControllerEvent&) override {}
  void TxConfirmed(std::span<const TimedFrame> frames) override {
    confirmed += frames.size();
    for (std::size_t i = 0; i < frames.size(); ++i)
      submitted += broker_.Submit(id_, frame_);
  }
  std::uint64_t submitted = 0, confirmed = 0, received = 0;
  BusTime first_time{}, last_time{};  ///< ends of the first and last frame received

 private:
  Broker& broker_;
  CanFrame frame_;
  PortId id_ = 0;
};

struct PacedResult {
  double theoretical = 0;  ///< frames/s: bitrate / frame bits
  double achieved = 0;     ///< frames/s on the bus time line
  std::uint64_t frames = 0;
  std::uint64_t lost = 0;  ///< confirmed by a sender but not received by every other port
  double load_percent = 0;
  double wall_s = 0;
  double cpu_share = 0;
};

/// Two senders whose 8-byte frames have the same length on the wire, both always pending, and a
/// listener. The lower identifier wins every arbitration (as on a real bus at 100 % load); the
/// bus never idles, so achieved = theoretical when the time line has no gaps.
template <class Run>
PacedResult Paced(Scheduler& s, std::uint32_t bitrate, Run run) {
  Broker broker(s);
  broker.AddBus({.name = "bench", .bitrate = bitrate});
  const CanFrame first = EightBytes(0x181, 0xA5);
  CanFrame second = first;
  const std::uint32_t bits = CountFrameBits(first).total();
  for (std::uint32_t id = 0x182; id < 0x200; ++id) {
    second = EightBytes(id, 0xA5);
    if (CountFrameBits(second).total() == bits) break;
  }
  Saturator a(broker, first), b(broker, second), listener(broker, first);
  const PortId pa = broker.Attach("bench", "a", a);
  const PortId pb = broker.Attach("bench", "b", b);
  broker.Attach("bench", "listener", listener);
  // Enough queued ahead to ride out the event loop being descheduled for ~14 ms at 1 Mbit/s (a
  // node process queues ahead too); the broker itself adds no gaps (see the simulated rows).
  a.Start(pa, 128);
  b.Start(pb, 128);
  const double cpu0 = CpuSeconds();
  const auto t0 = Clock::now();
  run();
  PacedResult out;
  out.wall_s = Seconds(Clock::now() - t0);
  out.cpu_share = (CpuSeconds() - cpu0) / out.wall_s;
  out.theoretical = static_cast<double>(bitrate) / bits;
  out.frames = listener.received;
  // Frames per second between the ends of the first and the last frame (so the time the harness
  // took to submit the first frames does not count).
  const double bus_seconds = std::chrono::duration<double>(listener.last_time - listener.first_time).count();
  out.achieved = static_cast<double>(listener.received - 1) / bus_seconds;
  const std::uint64_t confirmed = a.confirmed + b.confirmed;
  out.lost = (confirmed - listener.received) + (a.confirmed - b.received) + (b.confirmed - a.received);
  out.load_percent = broker.Stats("bench").load_percent;
  return out;
}

PacedResult PacedSimulated(std::uint32_t bitrate, Duration bus_time) {
  SimulatedScheduler s;
  return Paced(s, bitrate, [&] { s.Advance(bus_time); });
}

PacedResult PacedRealTime(std::uint32_t bitrate, Duration wall) {
  asio::io_context io;
  AsioScheduler s(io);
  return Paced(s, bitrate, [&] { io.run_for(wall); });
}

/// A fixed amount of work, for instruction counts (valgrind --tool=callgrind): `rounds` rounds
/// of the simulated unpaced run, after 16 warm-up rounds.
int FixedRounds(int ports, std::uint64_t rounds, bool encode) {
  SimulatedScheduler s;
  UnpacedFleet fleet(s, ports, BatchFor(ports), encode);
  for (int i = 0; i < 16; ++i) {
    fleet.SubmitRound();
    s.Advance(1ns);
  }
  const std::uint64_t warm = fleet.Deliveries();
  for (std::uint64_t i = 0; i < rounds; ++i) {
    fleet.SubmitRound();
    s.Advance(1ns);
  }
  std::printf("ports %d, %s: %llu rounds, %llu deliveries\n", ports, encode ? "encode" : "count",
              static_cast<unsigned long long>(rounds),
              static_cast<unsigned long long>(fleet.Deliveries() - warm));
  return 0;
}

}  // namespace
}  // namespace canfleet::broker

int main(int argc, char** argv) {
  using namespace canfleet::broker;
  if (argc > 1 && std::string(argv[1]) == "--rounds") {
    // canfleet_broker_bench --rounds N PORTS [encode]
    if (argc < 4) {
      std::fprintf(stderr, "usage: canfleet_broker_bench --rounds ROUNDS PORTS [encode]\n");
      return 2;
    }
    return FixedRounds(std::atoi(argv[3]), std::strtoull(argv[2], nullptr, 10),
                       argc > 4 && std::string(argv[4]) == "encode");
  }
  const double seconds = argc > 1 ? std::atof(argv[1]) : 1.0;

  std::printf("canfleet broker, in process (%u hardware threads)\n\n", std::thread::hardware_concurrency());

  std::printf("Unpaced throughput (every port sends a batch per round, receives all others)\n");
  std::printf("| ports | driver    | deliveries/s | frames/s   | CPU  | deliveries per CPU-s |\n");
  std::printf("|------:|-----------|-------------:|-----------:|-----:|---------------------:|\n");
  for (int ports : {2, 8, 32}) {
    const Throughput sim = UnpacedSimulated(ports, seconds, false);
    std::printf("| %5d | simulated | %12.0f | %10.0f | %3.0f%% | %20.0f |\n", ports, sim.deliveries_per_s,
                sim.frames_per_s, 100 * sim.cpu_share, sim.deliveries_per_s / sim.cpu_share);
    const Throughput wire = UnpacedSimulated(ports, seconds, true);
    std::printf("| %5d | sim+wire  | %12.0f | %10.0f | %3.0f%% | %20.0f |\n", ports, wire.deliveries_per_s,
                wire.frames_per_s, 100 * wire.cpu_share, wire.deliveries_per_s / wire.cpu_share);
    const Throughput real = UnpacedAsio(ports, seconds);
    std::printf("| %5d | asio      | %12.0f | %10.0f | %3.0f%% | %20.0f |\n", ports, real.deliveries_per_s,
                real.frames_per_s, 100 * real.cpu_share, real.deliveries_per_s / real.cpu_share);
  }

  std::printf("\nUnpaced Submit -> Deliver latency, one frame in flight (asio event loop, in process)\n");
  std::printf("| ports | samples | p50 us | p99 us |\n");
  std::printf("|------:|--------:|-------:|-------:|\n");
  for (int ports : {2, 8, 32}) {
    const Latency l = UnpacedLatency(ports, 20000);
    std::printf("| %5d | %7zu | %6.1f | %6.1f |\n", ports, l.samples, l.p50_us, l.p99_us);
  }

  std::printf(
      "\nPaced, 100%% offered load (2 saturating senders, 8-byte frames of equal length, 1 listener;\n"
      "the lower identifier wins every arbitration, as on a real bus)\n");
  std::printf(
      "| bitrate | driver               | theoretical f/s | achieved f/s |"
      " ratio    | frames | lost | load %%  | CPU  |\n");
  std::printf(
      "|--------:|----------------------|----------------:|-------------:|"
      "---------:|-------:|-----:|--------:|-----:|\n");
  for (std::uint32_t bitrate : {125'000u, 1'000'000u}) {
    const PacedResult sim = PacedSimulated(bitrate, std::chrono::seconds(10));
    std::printf("| %7u | %-20s | %15.2f | %12.2f | %8.6f | %6llu | %4llu | %7.3f | %3.0f%% |\n", bitrate,
                "simulated 10 s", sim.theoretical, sim.achieved, sim.achieved / sim.theoretical,
                static_cast<unsigned long long>(sim.frames), static_cast<unsigned long long>(sim.lost),
                sim.load_percent, 100 * sim.cpu_share);
    const auto wall =
        std::chrono::duration_cast<canfleet::Duration>(std::chrono::duration<double>(2 * seconds));
    const PacedResult real = PacedRealTime(bitrate, wall);
    char label[32];
    std::snprintf(label, sizeof label, "asio real time %.1f s", 2 * seconds);
    std::printf("| %7u | %-20s | %15.2f | %12.2f | %8.6f | %6llu | %4llu | %7.3f | %3.0f%% |\n", bitrate,
                label, real.theoretical, real.achieved, real.achieved / real.theoretical,
                static_cast<unsigned long long>(real.frames), static_cast<unsigned long long>(real.lost),
                real.load_percent, 100 * real.cpu_share);
  }
  return 0;
}
