// Cross-process transport benchmark (issue 4, "Benchmark"): prints a table, it is not a test.
//
// For 2, 8 and 32 node processes on one unpaced bus of a real canfleet-broker process, over Unix
// sockets and over TCP, and for the same traffic through a raw Unix-socket relay (the machine's
// IPC limit: a process that only forwards bytes):
//   - deliveries/s: frames received by all nodes per second (a frame to 31 nodes is 31), every
//     node sending as fast as its window allows (roles.hpp);
//   - node -> node latency p50/p99 at light load: node 0 sends 2000 frames/s, the others measure
//     CLOCK_MONOTONIC send time (in the frame) -> receive time;
//   - the same latency under full load, for honesty: it is mostly queueing behind the window.
//
// Usage: canfleet_transport_bench [seconds per measurement, default 2] [ports list, default 2,8,32]
// The same binary is also the node ("client ...") and the relay ("relay ...") processes.

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <sys/utsname.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "bench/transport/bench_process.hpp"
#include "bench/transport/latency_histogram.hpp"
#include "bench/transport/roles.hpp"

namespace canfleet::bench {
namespace {

/// The broker under test: CANFLEET_BENCH_BROKER when set (to compare two builds in one run, runs
/// interleaved), else the one built with this benchmark.
std::string BrokerProgram() {
  const char* other = std::getenv("CANFLEET_BENCH_BROKER");
  return other != nullptr && *other != '\0' ? other : PROGRAM_CANFLEET_BROKER;
}

using namespace std::chrono_literals;

enum class Path { kRaw, kRawTcp, kUnix, kTcp };

const char* Name(Path path) {
  switch (path) {
    case Path::kRaw:
      return "raw relay (unix)";
    case Path::kRawTcp:
      return "raw relay (tcp)";
    case Path::kUnix:
      return "broker, unix";
    case Path::kTcp:
      return "broker, tcp";
  }
  return "?";
}

/// CANFLEET_BENCH_PATHS (e.g. "unix" or "raw,tcp") limits a run to some paths, for profiling one
/// of them alone; "vs raw" is then empty unless raw runs too.
bool Selected(Path path) {
  const char* list = std::getenv("CANFLEET_BENCH_PATHS");
  if (list == nullptr || *list == '\0') return true;
  const std::string paths = std::string(",") + list + ",";
  const char* key = path == Path::kRaw      ? ",raw,"
                    : path == Path::kRawTcp ? ",rawtcp,"
                    : path == Path::kUnix   ? ",unix,"
                                            : ",tcp,";
  return paths.find(key) != std::string::npos;
}

struct Options {
  double seconds = 2;
  std::vector<int> ports = {2, 8, 32};
  std::size_t window = 128;
  double rate = 2000;
};

struct Result {
  double deliveries_per_s = 0;
  double server_cpu = 0;  ///< broker or relay CPU, fraction of one core, over the window
  double nodes_cpu = 0;   ///< all node processes together, fraction of one core, over the window
  LatencyHistogram latency;
  std::uint64_t kicks = 0;
  std::uint64_t writes = 0;  ///< client socket writes (broker clients)
  std::uint64_t sent = 0;
};

std::string Self() {
  return std::filesystem::read_symlink("/proc/self/exe").string();
}

class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/cfbench.XXXXXX";
    if (::mkdtemp(tmpl) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  std::string File(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

Result Run(Path path, int ports, bool latency, const Options& o) {
  TempDir dir;
  std::unique_ptr<BenchProcess> server;
  std::string endpoint;
  const bool raw = path == Path::kRaw || path == Path::kRawTcp;
  if (raw) {
    server = std::make_unique<BenchProcess>(std::vector<std::string>{
        Self(), "relay", path == Path::kRawTcp ? "tcp" : dir.File("relay.sock"), std::to_string(ports)});
    const auto ready = server->ReadLine(10s);
    if (!ready || !ready->starts_with("ready ")) throw std::runtime_error("relay did not start");
    endpoint = ready->substr(6);
  } else {
    const std::string ready = dir.File("ready");
    server = std::make_unique<BenchProcess>(std::vector<std::string>{
        BrokerProgram(), "--bus", "can0:1M:unpaced", "--listen",
        path == Path::kTcp ? "tcp://127.0.0.1:0" : "unix://" + dir.File("broker.sock"), "--ready-file", ready,
        "--log-level", "warn"});
    const auto deadline = std::chrono::steady_clock::now() + 10s;
    while (!std::filesystem::exists(ready)) {
      if (std::chrono::steady_clock::now() > deadline) throw std::runtime_error("broker did not start");
      std::this_thread::sleep_for(5ms);
    }
    std::ifstream in(ready);
    std::getline(in, endpoint);
  }

  std::vector<std::unique_ptr<BenchProcess>> clients;
  for (int i = 0; i < ports; ++i)
    clients.push_back(std::make_unique<BenchProcess>(std::vector<std::string>{
        Self(), "client", raw ? "raw" : "broker", endpoint, std::to_string(i), std::to_string(ports),
        std::to_string(o.window), latency ? "latency" : "throughput", std::to_string(o.rate)}));
  for (auto& c : clients)
    if (c->ReadLine(20s) != "ready") throw std::runtime_error("a node did not connect");

  const std::int64_t start = MonotonicNs() + 300'000'000;  // warm-up
  const std::int64_t end = start + static_cast<std::int64_t>(o.seconds * 1e9);
  const std::int64_t stop = end + 100'000'000;
  for (auto& c : clients)
    c->WriteLine("go " + std::to_string(start) + " " + std::to_string(end) + " " + std::to_string(stop));
  auto sleep_until = [](std::int64_t ns) {
    std::this_thread::sleep_until(std::chrono::steady_clock::time_point(std::chrono::nanoseconds(ns)));
  };
  auto nodes_cpu = [&] {
    std::chrono::duration<double> total{0};
    for (auto& c : clients)
      total += c->CpuTime();
    return total;
  };
  sleep_until(start);
  const auto cpu_start = server->CpuTime();
  const auto nodes_start = nodes_cpu();
  sleep_until(end);
  const auto cpu_end = server->CpuTime();
  const auto nodes_end = nodes_cpu();

  Result r;
  std::uint64_t rx = 0;
  for (auto& c : clients) {
    const auto line = c->ReadLine(20s);
    if (!line || !line->starts_with("result ")) throw std::runtime_error("a node gave no result");
    std::istringstream in(line->substr(7));
    std::map<std::string, std::string> fields;
    for (std::string item; in >> item;) {
      const auto eq = item.find('=');
      fields[item.substr(0, eq)] = item.substr(eq + 1);
    }
    rx += std::stoull(fields["rx"]);
    r.kicks += std::stoull(fields["kicks"]);
    r.writes += std::stoull(fields["writes"]);
    r.sent += std::stoull(fields["sent"]);
    r.latency.Merge(LatencyHistogram::Parse(fields["hist"]));
  }
  server->Stop();
  r.deliveries_per_s = static_cast<double>(rx) / o.seconds;
  r.server_cpu = (cpu_end - cpu_start).count() / o.seconds;
  r.nodes_cpu = (nodes_end - nodes_start).count() / o.seconds;
  return r;
}

std::string Machine() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string model = "unknown CPU";
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.starts_with("model name")) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  }
  utsname u{};
  ::uname(&u);
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " hardware threads, Linux " +
         u.release;
}

std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  in >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

int Driver(const Options& o) {
  std::printf("canfleet transport: node processes <-> canfleet-broker (unpaced bus) vs a raw relay\n");
  std::printf("machine: %s; load average before the run: %s\n", Machine().c_str(), LoadAverage().c_str());
  std::printf(
      "%.1f s per measurement, window %zu frames per node, light load = %.0f frames/s from one node\n",
      o.seconds, o.window, o.rate);
  std::printf(
      "server CPU: broker (or relay) CPU time / wall time; ns/delivery: that CPU time per delivery;\n"
      "node ns/delivery: the CPU time of all node processes together per delivery\n\n");
  std::printf(
      "| path              | ports | deliveries/s | frames/s  | vs raw | vs raw tcp | server CPU | "
      "ns/delivery |"
      " node ns/delivery | p50 us | p99 us | loaded p50 us | loaded p99 us |\n");
  std::printf(
      "|-------------------|------:|-------------:|----------:|-------:|-----------:|-----------:|-----------"
      "-:|"
      "-----------------:|-------:|-------:|--------------:|--------------:|\n");
  for (int ports : o.ports) {
    double raw = 0;
    double raw_tcp = 0;
    for (Path path : {Path::kRaw, Path::kRawTcp, Path::kUnix, Path::kTcp}) {
      if (!Selected(path)) continue;
      const Result t = Run(path, ports, false, o);
      const Result l = Run(path, ports, true, o);
      if (path == Path::kRaw) raw = t.deliveries_per_s;
      if (path == Path::kRawTcp) raw_tcp = t.deliveries_per_s;
      // "vs raw": against the Unix-socket relay, the machine's IPC limit; for TCP also against
      // the TCP relay, the same traffic on the same kernel path.
      const double vs_tcp = path == Path::kTcp && raw_tcp > 0 ? 100 * t.deliveries_per_s / raw_tcp : 0;
      std::printf(
          "| %-17s | %5d | %12.0f | %9.0f | %5.0f%% | %9.0f%% | %9.0f%% | %11.0f | %16.0f | %6.1f | %6.1f | "
          "%13.1f | %13.1f |\n",
          Name(path), ports, t.deliveries_per_s, t.deliveries_per_s / (ports - 1),
          raw > 0 ? 100 * t.deliveries_per_s / raw : 0, vs_tcp, 100 * t.server_cpu,
          t.deliveries_per_s > 0 ? 1e9 * t.server_cpu / t.deliveries_per_s : 0,
          t.deliveries_per_s > 0 ? 1e9 * t.nodes_cpu / t.deliveries_per_s : 0, l.latency.Percentile(0.5),
          l.latency.Percentile(0.99), t.latency.Percentile(0.5), t.latency.Percentile(0.99));
      if (t.kicks != 0)
        std::printf(
            "(%s, %d ports: %llu stall kicks: a node saw no progress for 200 ms and went beyond its "
            "window)\n",
            Name(path), ports, static_cast<unsigned long long>(t.kicks));
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace
}  // namespace canfleet::bench

int main(int argc, char** argv) {
  using namespace canfleet::bench;
  try {
    const std::vector<std::string> args(argv + 1, argv + argc);
    if (!args.empty() && args[0] == "relay" && args.size() == 3) return RunRelay(args[1], std::stoi(args[2]));
    if (!args.empty() && args[0] == "client" && args.size() == 8) {
      // stdout is the driver's channel: logs go to stderr, and only what matters.
      spdlog::set_default_logger(spdlog::stderr_color_mt("bench-node"));
      spdlog::set_level(spdlog::level::warn);
      ClientConfig c;
      c.endpoint = args[2];
      c.index = std::stoi(args[3]);
      c.ports = std::stoi(args[4]);
      c.window = std::stoul(args[5]);
      c.latency = args[6] == "latency";
      c.rate = std::stod(args[7]);
      return args[1] == "raw" ? RunRawClient(c) : RunBrokerClient(c);
    }
    Options o;
    if (args.size() >= 1) o.seconds = std::stod(args[0]);
    if (args.size() >= 2) {
      o.ports.clear();
      std::istringstream in(args[1]);
      for (std::string p; std::getline(in, p, ',');)
        o.ports.push_back(std::stoi(p));
    }
    return Driver(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "canfleet_transport_bench: %s\n", e.what());
    return 1;
  }
}
