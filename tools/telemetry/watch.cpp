#include "tools/telemetry/watch.hpp"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <iostream>

#include "telemetry/cli_options.hpp"
#include "telemetry/fleet_reader.hpp"
#include "tools/telemetry/event_format.hpp"
#include "tools/telemetry/nothing_seen.hpp"

namespace canfleet::tools {

namespace {

std::atomic<bool> g_stop{false};
std::atomic<telemetry::FleetReader*> g_reader{nullptr};

extern "C" void OnWatchStopSignal(int) {
  g_stop = true;
  if (auto* reader = g_reader.load()) reader->Wake();  // dds_waitset_set_trigger, as pong.c does
}

}  // namespace

void AddWatchOptions(CLI::App& app, WatchOptions& options) {
  telemetry::AddDdsOptions(app, options.dds);
  app.add_flag("--json", options.json, "JSON lines instead of text");
  app.add_option("--bus", options.bus, "only events of this bus");
  app.add_option("--node", options.node, "only events of this node-id")->check(CLI::Range(0, 127));
  app.add_option_function<std::vector<std::string>>(
         "--type",
         [&options](const std::vector<std::string>& names) {
           for (const auto& name : names) {
             const auto kind = ParseEventKind(name);
             if (!kind) throw CLI::ValidationError("--type", "unknown event type '" + name + "'");
             options.kinds.insert(*kind);
           }
         },
         "event types: emcy nmt controller error-register hb-consumer fault verdict gone seen (default: "
         "all but seen)")
      ->delimiter(',');
  app.add_flag("--history", options.history,
               "also print the events from before watch started (kept by DDS, flagged [history]); default: "
               "only what happens from now on");
  // The default since issue 29; kept so that scripts written for the old default still run.
  app.add_flag("!--no-history", options.history, "(the default) only events from now on")->group("");
  app.add_option("--count", options.count, "exit after this many events")->check(CLI::NonNegativeNumber);
  app.add_option_function<double>(
      "--timeout",
      [&options](double s) { options.timeout = std::chrono::milliseconds(static_cast<long>(s * 1000)); },
      "exit after this many seconds (exit code 1 if --count events were not seen by then)");
}

bool Selected(const FleetEvent& event, const WatchOptions& options) {
  if (!options.bus.empty() && event.bus != options.bus) return false;
  if (options.node >= 0 && event.node_id != options.node) return false;
  if (!options.history && event.replay) return false;
  if (options.kinds.empty()) return event.kind != EventKind::kNodeSeen || !event.from.empty();
  return options.kinds.contains(event.kind);
}

int RunWatch(const WatchOptions& options) {
  std::ostream& out = options.out ? *options.out : std::cout;
  std::ostream& err = options.err ? *options.err : std::cerr;
  bool hinted = options.hint_after.count() == 0;
  const auto started = std::chrono::steady_clock::now();
  telemetry::Participant participant(options.dds);
  FleetView view(std::chrono::system_clock::now());
  std::vector<FleetEvent> events;
  telemetry::FleetReader reader(
      participant, {.node_status = [&](const auto& s, const auto& m) { view.Apply(s, m, &events); },
                    .emcy = [&](const auto& s, const auto& m) { view.Apply(s, m, &events); },
                    .io = {},
                    .bus_stats = {},
                    .fault = [&](const auto& s, const auto& m) { view.Apply(s, m, &events); },
                    .verdict = [&](const auto& s, const auto& m) { view.Apply(s, m, &events); }});

  g_stop = false;
  g_reader = &reader;
  auto* previous_int = std::signal(SIGINT, OnWatchStopSignal);
  auto* previous_term = std::signal(SIGTERM, OnWatchStopSignal);
  int printed = 0;
  int result = -1;
  while (result < 0) {
    auto wait = std::chrono::milliseconds(1000);
    if (options.timeout.count() > 0) {
      const auto left = options.timeout - std::chrono::duration_cast<std::chrono::milliseconds>(
                                              std::chrono::steady_clock::now() - started);
      if (left <= std::chrono::milliseconds::zero()) {
        result = 0;
        if (options.count > 0 && printed < options.count) {
          err << "canfleet watch: " << printed << " of " << options.count << " events within the timeout\n";
          result = 1;
        }
        break;
      }
      wait = std::min(wait, left);
    }
    reader.Wait(wait);
    if (g_stop) {
      result = 0;
      break;
    }
    reader.Poll();
    if (!hinted && view.nodes().empty() && view.buses().empty() &&
        std::chrono::steady_clock::now() - started >= options.hint_after) {
      err << NothingSeenHint("canfleet watch", options.dds) << std::endl;
      hinted = true;
    }
    // One poll delivers topic by topic: print in time order.
    std::stable_sort(events.begin(), events.end(),
                     [](const auto& a, const auto& b) { return a.time < b.time; });
    for (const FleetEvent& event : events) {
      if (!Selected(event, options)) continue;
      out << (options.json ? FormatEventJson(event) : FormatEventText(event)) << '\n';
      ++printed;
      if (options.count > 0 && printed >= options.count) {
        result = 0;
        break;
      }
    }
    out.flush();
    events.clear();
  }
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  g_reader = nullptr;
  out.flush();
  return result;
}

}  // namespace canfleet::tools
