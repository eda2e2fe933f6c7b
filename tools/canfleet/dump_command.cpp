// canfleet dump [--bus B] [--id ID] [--mask M] [--error-frames] [--count N] [--json]: live frames
// in candump's log format until Ctrl-C.
#include <csignal>
#include <cstdio>
#include <iostream>
#include <memory>

#include "orchestrator/control/control_client.hpp"
#include "tools/canfleet/cli.hpp"
#include "tools/canfleet/text_format.hpp"

namespace canfleet::cli {

namespace {

volatile std::sig_atomic_t g_stop = 0;

extern "C" void OnDumpStopSignal(int) {
  g_stop = 1;
}

/// SIGINT/SIGTERM set a flag (no SA_RESTART, so a waiting poll returns at once); a closed stdout
/// (dump | head) shows as a failed write instead of killing us with SIGPIPE.
void InstallSignalHandlers() {
  struct sigaction action {};
  action.sa_handler = OnDumpStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
}

struct DumpArgs {
  std::string bus;
  std::string id;
  std::string mask;
  bool error_frames = false;
  std::uint64_t count = 0;
  bool json = false;
};

/// How often the wait for frames looks at the stop flag even without a signal.
constexpr std::chrono::milliseconds kPoll{200};

int RunDump(const GlobalOptions& global, const DumpArgs& a) {
  control::Request request;
  auto* body = request.mutable_dump();
  body->set_bus(a.bus);
  if (!a.id.empty()) body->set_cob_id(ParseHex(a.id, "--id", 0x1FFFFFFF));
  if (!a.mask.empty()) body->set_mask(ParseHex(a.mask, "--mask", 0x1FFFFFFF));
  body->set_error_frames(a.error_frames);

  InstallSignalHandlers();
  try {
    control::ControlClient client(global.control);
    const std::uint64_t id = client.Send(request);
    std::uint64_t printed = 0;
    while (g_stop == 0) {
      const auto response = client.Receive(kPoll);
      if (!response || response->id() != id) continue;
      if (!response->error().empty()) throw CommandError(response->error());
      for (const auto& frame : response->frames().frames()) {
        if (a.json)
          PrintJson(frame, true);
        else
          std::cout << FormatFrame(frame);
        if (a.count != 0 && ++printed == a.count) break;
      }
      std::cout.flush();
      if (!std::cout) return kExitOk;  // the reader went away (dump | head)
      if (a.count != 0 && printed >= a.count) return kExitOk;
    }
    return kExitOk;  // Ctrl-C: the normal way to end a dump
  } catch (const control::ControlError& e) {
    throw CommandError(e.what());
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

}  // namespace

void AddDumpCommand(CLI::App& app, Cli& cli) {
  auto a = std::make_shared<DumpArgs>();
  CLI::App* dump = app.add_subcommand("dump", "Print live frames in candump's log format until Ctrl-C");
  auto* bus = dump->add_option("--bus", a->bus, "Only this bus (default: every bus)");
  dump->add_option("BUS", a->bus, "The same as --bus")->excludes(bus);
  dump->add_option("--id", a->id, "Only frames with this identifier, in hex (0x185 or 185h)")
      ->check(HexValidator(0x1FFFFFFF));
  dump->add_option("--mask", a->mask, "Compare identifiers under this mask, in hex (default: all bits)")
      ->check(HexValidator(0x1FFFFFFF));
  dump->add_flag("--error-frames", a->error_frames, "Include error frames");
  dump->add_option("--count", a->count, "Stop after this many frames");
  dump->add_flag("--json", a->json, "One Frame message as JSON per line instead");
  dump->callback([&cli, a] { cli.action = [&cli, a] { return RunDump(cli.global, *a); }; });
}

}  // namespace canfleet::cli
