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
  // The orchestrator resolves relative paths against its own working directory; the user means
  // theirs.
  body->set_path(std::filesystem::absolute(a.file).lexically_normal().string());
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
  start->add_option("--file", a->file, "Where to write (relative to the current folder)")->required();
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
