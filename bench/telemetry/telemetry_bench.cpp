// Telemetry benchmark (issue 7): what publishing costs a node and how fast a fault reaches a reader.
//
//  1. Caller side: the cost of NodeTelemetry::UpdateStatus / PublishEmcy on the node's event loop
//     (the only part on the CAN path), with the publisher thread running.
//  2. CPU per node at 1 Hz and 100 Hz status: canfleet-fake-fleet children publishing N nodes,
//     measured with getrusage of the child (user + system, all its threads), minus a child with a
//     participant and no nodes; a monitor (this process) subscribes so the data really flows.
//  3. Fault to sample: P publisher processes, each sending an EMCY every 0.5 s (and one orchestrator
//     process toggling a fault, FaultEvent); this process takes the samples and measures
//     receive time - source timestamp (one host, one clock).
//  4. RSS of a node-like process (participant + NodeStatus/IoSnapshot/Emcy writers).
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "telemetry/fleet_reader.hpp"
#include "telemetry/node_telemetry.hpp"

namespace {

using namespace canfleet::telemetry;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

/// A canfleet-fake-fleet child; stdout to a pipe (we read its "stats" line), stderr inherited.
class Child {
 public:
  explicit Child(const std::vector<std::string>& args) {
    int out[2];
    if (pipe(out) != 0) throw std::runtime_error("pipe");
    pid_ = fork();
    if (pid_ == 0) {
      dup2(out[1], STDOUT_FILENO);
      close(out[0]);
      close(out[1]);
      const int null = open("/dev/null", O_RDONLY);
      dup2(null, STDIN_FILENO);
      std::vector<char*> argv;
      for (const auto& a : args)
        argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(argv[0], argv.data());
      _exit(127);
    }
    close(out[1]);
    out_ = out[0];
  }
  ~Child() {
    if (pid_ > 0 && !reaped_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    if (out_ >= 0) close(out_);
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  pid_t pid() const { return pid_; }
  /// Reads stdout up to EOF (the child has exited), reaps it and returns its rusage.
  rusage Finish(std::string* output) {
    char buffer[4096];
    for (ssize_t n; (n = read(out_, buffer, sizeof buffer)) > 0;)
      output->append(buffer, static_cast<std::size_t>(n));
    int status = 0;
    rusage usage{};
    wait4(pid_, &status, 0, &usage);
    reaped_ = true;
    return usage;
  }
  /// Reads stdout until a line starting with `prefix`.
  bool WaitFor(const std::string& prefix, std::chrono::seconds timeout = 60s) {
    const auto deadline = Clock::now() + timeout;
    std::string line;
    char c;
    while (Clock::now() < deadline && read(out_, &c, 1) == 1) {
      if (c != '\n') {
        line += c;
        continue;
      }
      if (line.rfind(prefix, 0) == 0) return true;
      line.clear();
    }
    return false;
  }

 private:
  pid_t pid_ = -1;
  int out_ = -1;
  bool reaped_ = false;
};

std::vector<std::string> FakeFleet(std::uint32_t domain, std::vector<std::string> extra) {
  std::vector<std::string> args = {CANFLEET_FAKE_FLEET, "--dds-domain", std::to_string(domain),
                                   "--dds-config", CANFLEET_DDS_LOOPBACK_CONFIG};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

double CpuSeconds(const rusage& usage) {
  const auto tv = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6;
  };
  return tv(usage.ru_utime) + tv(usage.ru_stime);
}

long Field(const std::string& text, const std::string& key) {
  const auto at = text.rfind(key + "=");
  return at == std::string::npos ? -1 : std::stol(text.substr(at + key.size() + 1));
}

/// A monitor that keeps the publishers' data flowing and counts what it receives.
struct Monitor {
  explicit Monitor(std::uint32_t domain)
      : participant({.domain_id = domain, .config_file = CANFLEET_DDS_LOOPBACK_CONFIG}),
        reader(participant, {.node_status = [this](const auto& s, const auto& m) { OnStatus(s, m); },
                             .emcy = [this](const auto& s, const auto& m) { OnEvent(s.bus, m); },
                             .io = {},
                             .bus_stats = {},
                             .fault = [this](const auto& s, const auto& m) { OnFault(s, m); }}) {}

  void OnStatus(const NodeStatusSample& s, const SampleMeta& m) {
    if (m.valid_data) {
      ++statuses;
      nodes.insert(s.node_id);
    }
  }
  void OnEvent(const std::string&, const SampleMeta& m) {
    if (!m.valid_data || !recording) return;
    emcy_latency.push_back(std::chrono::system_clock::now() - m.source_time);
  }
  void OnFault(const FaultEventSample&, const SampleMeta& m) {
    if (!m.valid_data || !recording) return;
    fault_latency.push_back(std::chrono::system_clock::now() - m.source_time);
  }
  /// Takes samples as they arrive (a waitset wakes us) for `duration`.
  void Run(std::chrono::milliseconds duration) {
    const auto end = Clock::now() + duration;
    while (Clock::now() < end) {
      reader.Wait(10ms);
      reader.Poll();
    }
  }

  Participant participant;
  FleetReader reader;
  std::uint64_t statuses = 0;
  std::set<int> nodes;
  bool recording = false;
  std::vector<std::chrono::system_clock::duration> emcy_latency;
  std::vector<std::chrono::system_clock::duration> fault_latency;
};

std::string Percentiles(std::vector<std::chrono::system_clock::duration> samples) {
  if (samples.empty()) return "no samples";
  std::sort(samples.begin(), samples.end());
  const auto ms = [&](double q) {
    const auto i =
        std::min(samples.size() - 1, static_cast<std::size_t>(q * static_cast<double>(samples.size())));
    return std::chrono::duration<double, std::milli>(samples[i]).count();
  };
  char text[160];
  std::snprintf(text, sizeof text, "p50 %6.2f ms  p99 %6.2f ms  max %6.2f ms  (n=%zu)", ms(0.5), ms(0.99),
                ms(1.0), samples.size());
  return text;
}

void CallerCost() {
  Participant participant({.domain_id = 150, .config_file = CANFLEET_DDS_LOOPBACK_CONFIG});
  NodeTelemetry telemetry(participant, {.bus = "bench", .node_id = 1, .period = 10ms, .min_interval = 20ms});
  NodeStatusSnapshot status;
  status.heartbeat_consumer_count = 16;
  constexpr int kCalls = 2'000'000;
  auto start = Clock::now();
  for (int i = 0; i < kCalls; ++i) {
    status.rpdo_count = static_cast<std::uint64_t>(i);
    status.tec = static_cast<std::uint16_t>(i & 0xFF);  // a real change every call
    telemetry.UpdateStatus(status);
  }
  const double update_ns = std::chrono::duration<double, std::nano>(Clock::now() - start).count() / kCalls;
  constexpr int kEmcys = 200'000;
  start = Clock::now();
  for (int i = 0; i < kEmcys; ++i)
    telemetry.PublishEmcy({.code = 0x1000});
  const double emcy_ns = std::chrono::duration<double, std::nano>(Clock::now() - start).count() / kEmcys;
  telemetry.Flush();
  const auto stats = telemetry.stats();
  std::printf(
      "| caller: UpdateStatus (%zu B snapshot, change every call) | %.0f ns/call | %llu writes for %d "
      "updates |\n",
      sizeof(NodeStatusSnapshot), update_ns, static_cast<unsigned long long>(stats.state_writes), kCalls);
  std::printf(
      "| caller: PublishEmcy (queue 64, excess dropped) | %.0f ns/call | %llu written, %llu dropped |\n",
      emcy_ns, static_cast<unsigned long long>(stats.event_writes),
      static_cast<unsigned long long>(stats.events_dropped));
}

/// CPU seconds per second of one fake-fleet child publishing `nodes` nodes at `period`.
double ChildCpu(std::uint32_t domain, int nodes, double period, double seconds, std::string* output,
                long* switches = nullptr) {
  Monitor monitor(domain);
  Child child(
      FakeFleet(domain, {"--nodes", std::to_string(nodes), "--period", std::to_string(period), "--update",
                         std::to_string(std::min(period, 0.1)), "--duration", std::to_string(seconds)}));
  monitor.Run(std::chrono::milliseconds(static_cast<long>(seconds * 1000)));
  const rusage usage = child.Finish(output);
  if (switches)
    *switches = static_cast<long>(static_cast<double>(usage.ru_nvcsw + usage.ru_nivcsw) / seconds);
  return CpuSeconds(usage) / seconds;
}

void CpuPerNode(double seconds) {
  std::string out;
  const double idle = ChildCpu(151, 0, 1.0, seconds, &out);
  std::printf("| process with a participant, no node | %.3f %% CPU | baseline, subtracted below |\n",
              idle * 100);
  for (const double period : {1.0, 0.01}) {
    for (const int nodes : {1, 20}) {
      out.clear();
      long switches = 0;
      const double cpu = ChildCpu(152, nodes, period, seconds, &out, &switches);
      const long writes = Field(out, "state_writes");
      std::printf(
          "| %d node%s in one process, status at %.0f Hz | %.3f %% CPU per node | %.0f status writes/s, %ld "
          "context "
          "switches/s, monitor subscribed |\n",
          nodes, nodes > 1 ? "s" : "", 1.0 / period, (cpu - idle) * 100 / nodes,
          static_cast<double>(writes) / seconds, switches);
    }
  }
}

void Latency(int publishers, int per_process, double seconds) {
  const std::uint32_t domain = 153 + static_cast<std::uint32_t>((publishers + per_process) % 30);
  Monitor monitor(domain);
  std::vector<std::unique_ptr<Child>> children;
  children.push_back(std::make_unique<Child>(
      FakeFleet(domain, {"--nodes", "0", "--orchestrator", "--fault-every", "0.5", "--first-node", "1"})));
  for (int i = 1; i <= publishers; i += per_process) {
    children.push_back(std::make_unique<Child>(
        FakeFleet(domain, {"--nodes", std::to_string(per_process), "--first-node", std::to_string(i),
                           "--emcy-every", "0.5", "--bus", "lat"})));
  }
  for (auto& child : children)
    child->WaitFor("ready");
  // Discovery: wait until every node's status has arrived, then measure.
  const auto start = Clock::now();
  while (static_cast<int>(monitor.nodes.size()) < publishers && Clock::now() - start < 90s)
    monitor.Run(100ms);
  const double discovery = std::chrono::duration<double>(Clock::now() - start).count();
  monitor.Run(1s);  // let the history drain
  monitor.recording = true;
  monitor.Run(std::chrono::milliseconds(static_cast<long>(seconds * 1000)));
  const std::string setup = std::to_string(publishers) + " nodes in " +
                            std::to_string((publishers + per_process - 1) / per_process) + " process" +
                            (per_process < publishers ? "es" : "");
  std::printf("| %s: EMCY write -> reader | %s | %zu of %d nodes seen, %.1f s after start |\n", setup.c_str(),
              Percentiles(monitor.emcy_latency).c_str(), monitor.nodes.size(), publishers, discovery);
  std::printf("| %s: FaultEvent write -> reader | %s | |\n", setup.c_str(),
              Percentiles(monitor.fault_latency).c_str());
}

void Memory() {
  for (const auto& [label, args] : std::vector<std::pair<std::string, std::vector<std::string>>>{
           {"participant only", {"--nodes", "0"}},
           {"node process: participant + NodeStatus/IoSnapshot/Emcy writers", {"--nodes", "1", "--io"}},
           {"orchestrator-like: + BusStats/FaultEvent writers",
            {"--nodes", "1", "--io", "--orchestrator"}}}) {
    Monitor monitor(190);  // a reader matched to the writers, as in a monitored fleet
    auto full = args;
    full.insert(full.end(), {"--duration", "3"});
    Child child(FakeFleet(190, full));
    monitor.Run(3s);
    std::string out;
    child.Finish(&out);
    std::printf("| RSS, %s | %.1f MB peak (VmHWM) | target < 10 MB per node process |\n", label.c_str(),
                static_cast<double>(Field(out, "hwm_kb")) / 1024.0);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Telemetry benchmark: prints a table"};
  double seconds = 10;
  std::vector<int> publisher_counts{20, 100};
  app.add_option("--seconds", seconds, "measurement time per CPU/latency figure")->capture_default_str();
  app.add_option("--publishers", publisher_counts, "publisher process counts for the latency figures")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  signal(SIGPIPE, SIG_IGN);
  try {
    std::printf("| measurement | figure | notes |\n|---|---|---|\n");
    CallerCost();
    CpuPerNode(seconds);
    for (const int n : publisher_counts)
      Latency(n, 1, seconds);   // one process per node, as the real fleet
    Latency(100, 20, seconds);  // 100 publishers in fewer DDS processes
    Memory();
  } catch (const std::exception& e) {
    std::cerr << "canfleet_telemetry_bench: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
