#include "web/run_web.hpp"

#include <spdlog/spdlog.h>

#include <atomic>
#include <csignal>
#include <fstream>
#include <iostream>
#include <thread>

#include "bus/wire/auth_token.hpp"
#include "telemetry/cli_options.hpp"
#include "telemetry/fleet_reader.hpp"
#include "web/bus_monitor.hpp"
#include "web/web_server.hpp"
#include "web/web_state.hpp"

namespace canfleet::web {

namespace {

std::atomic<bool> g_stop{false};
std::atomic<telemetry::FleetReader*> g_reader{nullptr};

extern "C" void OnStopSignal(int) {
  g_stop = true;
  if (auto* reader = g_reader.load()) reader->Wake();
}

}  // namespace

std::pair<std::string, std::uint16_t> ParseListen(const std::string& text) {
  const auto colon = text.rfind(':');
  const std::string address = colon == std::string::npos ? "127.0.0.1" : text.substr(0, colon);
  const std::string port = colon == std::string::npos ? text : text.substr(colon + 1);
  std::size_t used = 0;
  int value = -1;
  try {
    value = std::stoi(port, &used);
  } catch (const std::exception&) {
  }
  if (used != port.size() || value < 0 || value > 65535 || address.empty())
    throw std::invalid_argument("--listen " + text + ": [ADDRESS:]PORT, e.g. 127.0.0.1:8080 or 8080");
  const bool bracketed = address.size() > 2 && address.front() == '[' && address.back() == ']';
  return {bracketed ? address.substr(1, address.size() - 2) : address, static_cast<std::uint16_t>(value)};
}

std::filesystem::path StaticDir(const std::filesystem::path& given) {
  if (!given.empty()) return given;
  // Installed (the docker image: /usr/local/bin/canfleet, /usr/local/share/canfleet/web), else the
  // repository this binary was built from.
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const auto installed = exe.parent_path().parent_path() / "share" / "canfleet" / "web";
    if (std::filesystem::is_regular_file(installed / "index.html", ec)) return installed;
  }
  return CANFLEET_WEB_STATIC_DIR;
}

void AddWebOptions(CLI::App& app, WebOptions& options) {
  app.add_option(
         "--listen", options.listen,
         "[ADDRESS:]PORT to serve on (default 127.0.0.1:8080; beyond loopback, actions need the token "
         "printed at start)")
      ->capture_default_str();
  app.add_option("--static", options.static_dir,
                 "Folder of the page's files (default: the repository's web/static)");
  app.add_flag("--read-only", options.read_only, "No actions from the page (faults, I/O, NMT, SDO)");
  app.add_option("--token-file", options.token_file,
                 "File holding the token the page's actions must carry (default: CANFLEET_TOKEN_FILE, else "
                 "CANFLEET_TOKEN, else one made up and printed when actions are on beyond loopback)");
  app.add_option("--retention", options.retention_s, "Seconds of plots and timeline kept (default 600)")
      ->check(CLI::Range(10, 86400));
  app.add_option("--update-ms", options.update_ms, "Milliseconds between updates to the page (default 200)")
      ->check(CLI::Range(50, 10000));
  app.add_option("--broker", options.broker,
                 "Broker endpoint (tcp://HOST:PORT, unix:///path) to watch the buses as a monitor: heartbeat "
                 "period min/max/jitter, SDO response times, boot-ups per node");
  app.add_option("--ready-file", options.ready_file,
                 "Written once serving: \"url <url>\" (and \"token <token>\")");
  telemetry::AddDdsOptions(app, options.dds);  // a reader: it must discover the writers
}

int RunWeb(const WebOptions& options) {
  WebServerOptions server_options;
  try {
    std::tie(server_options.address, server_options.port) = ParseListen(options.listen);
  } catch (const std::invalid_argument& e) {
    std::cerr << "canfleet web: " << e.what() << '\n';
    return 2;
  }
  server_options.static_dir = StaticDir(options.static_dir);
  if (!std::filesystem::is_regular_file(server_options.static_dir / "index.html")) {
    std::cerr << "canfleet web: no index.html in " << server_options.static_dir << " (--static DIR)\n";
    return 2;
  }
  server_options.control = options.control;
  server_options.read_only = options.read_only;
  try {
    server_options.token = wire::ResolveToken(options.token_file).value_or("");
  } catch (const std::runtime_error& e) {
    std::cerr << "canfleet web: " << e.what() << '\n';
    return 2;
  }
  server_options.update_period = std::chrono::milliseconds(options.update_ms);

  const std::string fleet_token = server_options.token;
  WebStateOptions state_options;
  state_options.retention = std::chrono::seconds(options.retention_s);
  WebState state(std::chrono::system_clock::now(), state_options);
  std::unique_ptr<WebServer> server;
  try {
    server = std::make_unique<WebServer>(state, server_options);
  } catch (const std::exception& e) {
    std::cerr << "canfleet " << e.what() << '\n';
    return 2;
  }
  telemetry::Participant participant(options.dds);
  telemetry::FleetReader reader(participant,
                                {.node_status = [&](const auto& s, const auto& m) { state.Apply(s, m); },
                                 .emcy = [&](const auto& s, const auto& m) { state.Apply(s, m); },
                                 .io = [&](const auto& s, const auto& m) { state.Apply(s, m); },
                                 .bus_stats = [&](const auto& s, const auto& m) { state.Apply(s, m); },
                                 .fault = [&](const auto& s, const auto& m) { state.Apply(s, m); },
                                 .verdict = [&](const auto& s, const auto& m) { state.Apply(s, m); },
                                 .scenario = [&](const auto& s, const auto& m) { state.Apply(s, m); }});
  g_stop = false;
  g_reader = &reader;
  auto* previous_int = std::signal(SIGINT, OnStopSignal);
  auto* previous_term = std::signal(SIGTERM, OnStopSignal);

  std::cout << "canfleet web: " << server->Url() << (server->ActionsEnabled() ? "" : "  (read-only)") << '\n';
  if (server->ActionsEnabled() && !server->Token().empty())
    std::cout << "canfleet web: actions need the token " << server->Token() << '\n';
  std::cout.flush();
  if (!options.ready_file.empty()) {
    const auto tmp = options.ready_file.string() + ".tmp";
    {
      std::ofstream out(tmp, std::ios::trunc);
      out << "url " << server->Url() << "\n";
      if (!server->Token().empty()) out << "token " << server->Token() << "\n";
    }
    std::filesystem::rename(tmp, options.ready_file);
  }
  std::unique_ptr<BusMonitor> monitor;
  if (!options.broker.empty())
    monitor =
        std::make_unique<BusMonitor>(options.broker, fleet_token,
                                     [&state](const std::string& bus, const CanFrame& frame,
                                              std::int64_t time_ns) { state.Frame(bus, frame, time_ns); });
  std::thread serving([&] { server->Run(); });
  auto last_trim = std::chrono::steady_clock::now();
  while (!g_stop) {
    reader.Wait(std::chrono::milliseconds(200));
    reader.Poll();
    if (std::chrono::steady_clock::now() - last_trim > std::chrono::seconds(1)) {
      state.Trim(std::chrono::system_clock::now());
      last_trim = std::chrono::steady_clock::now();
      if (monitor)
        for (const auto& bus : state.BusNames())
          monitor->Watch(bus);
    }
  }
  g_reader = nullptr;
  server->Stop();
  serving.join();
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  return 0;
}

}  // namespace canfleet::web
