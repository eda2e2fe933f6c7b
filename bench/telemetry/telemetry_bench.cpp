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
//  5. A real canfleet-node (Quad controller, idle in pre-operational, on a canfleet-broker bus)
//     with telemetry at 1 Hz and with --no-telemetry: CPU from /proc/<pid>/stat over the
//     measurement (start-up excluded) and RSS from /proc/<pid>/status, a monitor subscribed.
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
#include <sstream>
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

/// utime + stime, seconds, from a /proc/.../stat file (fields 14 and 15).
double StatCpuSeconds(const std::string& path) {
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto close = text.rfind(')');  // the command name may contain spaces
  if (close == std::string::npos) return -1;
  std::istringstream fields(text.substr(close + 2));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && fields >> field; ++i) {
    if (i == 14) utime = std::stoull(field);
    if (i == 15) stime = std::stoull(field);
  }
  return static_cast<double>(utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

/// CPU seconds of a live process: all threads, and the main thread alone (the node's event loop;
/// the other threads are Cyclone's and the telemetry publisher's).
struct ProcessCpu {
  double total = 0;
  double main_thread = 0;
};
ProcessCpu ReadProcessCpu(pid_t pid) {
  const std::string dir = "/proc/" + std::to_string(pid);
  return {StatCpuSeconds(dir + "/stat"), StatCpuSeconds(dir + "/task/" + std::to_string(pid) + "/stat")};
}

/// A "VmRSS:"-style field of /proc/<pid>/status, kB.
long ProcessStatusKb(pid_t pid, const std::string& field) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind(field, 0) == 0) return std::stol(line.substr(field.size()));
  return -1;
}

/// The Cyclone configuration of every participant of the run (--dds-config): the loopback one by
/// default; cyclonedds-default.xml (multicast discovery) for 100 processes, see README.md.
std::string g_dds_config = CANFLEET_DDS_LOOPBACK_CONFIG;

std::vector<std::string> FakeFleet(std::uint32_t domain, std::vector<std::string> extra) {
  std::vector<std::string> args = {CANFLEET_FAKE_FLEET, "--dds-domain", std::to_string(domain),
                                   "--dds-config", g_dds_config};
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
      : participant({.domain_id = domain, .config_file = g_dds_config}),
        reader(participant, {.node_status = [this](const auto& s, const auto& m) { OnStatus(s, m); },
                             .emcy = [this](const auto& s, const auto& m) { OnEvent(s.bus, m); },
                             .io = [this](const auto&, const auto& m) { ios += m.valid_data ? 1 : 0; },
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
  std::uint64_t ios = 0;
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
  Participant participant({.domain_id = 150, .config_file = g_dds_config});
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

/// Section 5: a real node process, telemetry on (1 Hz) and off.
void RealNode(double seconds) {
  constexpr std::uint32_t kDomain = 195;
  const std::string ready = "/tmp/canfleet-telemetry-bench-" + std::to_string(getpid()) + ".ready";
  std::remove(ready.c_str());
  Child broker({CANFLEET_BROKER, "--bus", "bench0:500k", "--listen", "tcp://127.0.0.1:0", "--ready-file",
                ready, "--log-level", "warn", "--no-telemetry"});
  const auto start = Clock::now();
  while (!std::ifstream(ready) && Clock::now() - start < 30s)
    std::this_thread::sleep_for(20ms);
  std::string endpoint;
  std::getline(std::ifstream(ready) >> std::ws, endpoint);
  std::remove(ready.c_str());
  if (endpoint.empty()) throw std::runtime_error("canfleet-broker did not start");

  Monitor monitor(kDomain);
  for (const bool telemetry : {true, false}) {
    std::vector<std::string> args = {CANFLEET_NODE, "--device",     "quad-controller",       "--node-id",
                                     "5",           "--bus",        "bench0@" + endpoint,    "--log-level",
                                     "warn",        "--dds-domain", std::to_string(kDomain), "--dds-config",
                                     g_dds_config};
    if (!telemetry) args.push_back("--no-telemetry");
    Child node(args);
    monitor.Run(3s);  // start-up, connection, boot, discovery
    const std::uint64_t statuses_before = monitor.statuses;
    const std::uint64_t ios_before = monitor.ios;
    const ProcessCpu before = ReadProcessCpu(node.pid());
    const auto measured_from = Clock::now();
    monitor.Run(std::chrono::milliseconds(static_cast<long>(seconds * 1000)));
    const double elapsed = std::chrono::duration<double>(Clock::now() - measured_from).count();
    const ProcessCpu after = ReadProcessCpu(node.pid());
    const double cpu = (after.total - before.total) / elapsed;
    const double main_cpu = (after.main_thread - before.main_thread) / elapsed;
    const long rss = ProcessStatusKb(node.pid(), "VmRSS:");
    const long hwm = ProcessStatusKb(node.pid(), "VmHWM:");
    const long threads = ProcessStatusKb(node.pid(), "Threads:");
    std::printf(
        "| canfleet-node quad-controller, idle (pre-operational), telemetry %s | %.2f %% CPU (event loop "
        "%.2f %%, other threads %.3f %%), RSS %.1f MB (peak %.1f MB) | %ld threads, %.1f NodeStatus + "
        "%.1f IoSnapshot samples/s received |\n",
        telemetry ? "on at 1 Hz" : "off (--no-telemetry)", cpu * 100, main_cpu * 100, (cpu - main_cpu) * 100,
        static_cast<double>(rss) / 1024.0, static_cast<double>(hwm) / 1024.0, threads,
        static_cast<double>(monitor.statuses - statuses_before) / elapsed,
        static_cast<double>(monitor.ios - ios_before) / elapsed);
    kill(node.pid(), SIGTERM);
    std::string out;
    node.Finish(&out);
  }
  kill(broker.pid(), SIGTERM);
  std::string out;
  broker.Finish(&out);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Telemetry benchmark: prints a table"};
  double seconds = 10;
  std::vector<int> publisher_counts{20, 100};
  app.add_option("--seconds", seconds, "measurement time per CPU/latency figure")->capture_default_str();
  app.add_option("--dds-config", g_dds_config, "Cyclone DDS configuration of every participant")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  app.add_option("--publishers", publisher_counts, "publisher process counts for the latency figures")
      ->capture_default_str();
  std::set<std::string> sections{"caller", "cpu", "latency", "memory", "node"};
  app.add_option("--sections", sections, "which measurements: caller, cpu, latency, memory, node")
      ->check(CLI::IsMember({"caller", "cpu", "latency", "memory", "node"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  signal(SIGPIPE, SIG_IGN);
  try {
    std::printf("| measurement | figure | notes |\n|---|---|---|\n");
    if (sections.count("caller")) CallerCost();
    if (sections.count("cpu")) CpuPerNode(seconds);
    if (sections.count("latency")) {
      for (const int n : publisher_counts)
        Latency(n, 1, seconds);   // one process per node, as the real fleet
      Latency(100, 20, seconds);  // 100 publishers in fewer DDS processes
    }
    if (sections.count("memory")) Memory();
    if (sections.count("node")) RealNode(seconds);
  } catch (const std::exception& e) {
    std::cerr << "canfleet_telemetry_bench: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
