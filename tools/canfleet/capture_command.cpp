// canfleet capture start --bus B --file F [--format pcap|candump] [--json], canfleet capture stop [ID]
#include <filesystem>
#include <iostream>
#include <memory>

#include "tools/canfleet/cli.hpp"
#include "tools/canfleet/text_format.hpp"

namespace canfleet::cli {

namespace {

struct StartArgs {
  std::string bus;
  std::string file;
  std::string format = "pcap";
  bool json = false;
};

int RunStart(const GlobalOptions& global, const StartArgs& a) {
  control::Request request;
  auto* body = request.mutable_capture_start();
  body->set_bus(a.bus);
  // Sent as given: the orchestrator puts a relative file in the fleet's capture folder and writes
  // only inside the fleet's folders (orchestrator/fleet/capture_path.hpp); it answers with the
  // absolute path.
  body->set_path(a.file);
  body->set_format(a.format);
  const control::Response response = Call(global, request);
  if (a.json)
    PrintJson(response.capture());
  else
    std::cout << FormatCaptureStarted(response.capture(), a.bus);
  return kExitOk;
}

}  // namespace

void AddCaptureCommands(CLI::App& app, Cli& cli) {
  CLI::App* capture =
      app.add_subcommand("capture", "Record a bus to a file (pcap for Wireshark, or candump log)");
  capture->require_subcommand(1);

  auto a = std::make_shared<StartArgs>();
  CLI::App* start = capture->add_subcommand("start", "Start recording; prints the capture's id and file");
  start->add_option("--bus", a->bus, "The bus to record")->required();
  start
      ->add_option("--file", a->file,
                   "The file to write: relative to the fleet's capture folder (canfleet up --capture-dir, "
                   "default <state folder>/captures), or an absolute path inside it or the state folder")
      ->required();
  start->add_option("--format", a->format, "pcap (LINKTYPE_CAN_SOCKETCAN) or candump (log format)")
      ->check(CLI::IsMember({"pcap", "candump"}));
  start->add_flag("--json", a->json, "Print the CaptureStarted message as JSON");
  start->callback([&cli, a] { cli.action = [&cli, a] { return RunStart(cli.global, *a); }; });

  auto id = std::make_shared<std::uint32_t>(0);
  CLI::App* stop =
      capture->add_subcommand("stop", "Stop a capture (default: every capture) and close its file");
  stop->add_option("ID", *id, "The capture's id");
  stop->callback([&cli, id] {
    cli.action = [&cli, id] {
      control::Request request;
      request.mutable_capture_stop()->set_capture_id(*id);
      PrintDone(Call(cli.global, request), "stopped");
      return kExitOk;
    };
  });
}

}  // namespace canfleet::cli
