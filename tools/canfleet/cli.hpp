#pragma once
/// @file What every `canfleet` command shares: global options, exit codes, calling the
/// orchestrator, JSON output and the argument syntaxes (hex identifiers, durations).

#include <google/protobuf/message.h>
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "orchestrator/control/canfleet_control.pb.h"

namespace canfleet::cli {

/// Exit codes of every command.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailed = 1;  ///< the orchestrator answered with an error or is unreachable
inline constexpr int kExitUsage = 2;   ///< bad arguments

/// A bad argument found after CLI11's parsing (exit 2), e.g. an SDO value that does not fit its type.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The command failed (exit 1): the orchestrator's Response.error, or why it could not be reached.
class CommandError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct GlobalOptions {
  std::string control;                        ///< --control / CANFLEET_CONTROL
  bool control_given = false;                 ///< --control or CANFLEET_CONTROL was set
  std::chrono::milliseconds timeout{30'000};  ///< --timeout: how long to wait for a response
};

/// The parsed command line: the global options and what the chosen subcommand runs.
struct Cli {
  GlobalOptions global;
  std::function<int()> action;  ///< set by the chosen subcommand's callback
};

// One function per command group, each in its own file; each adds its subcommands to `app` and
// sets cli.action when chosen.
void AddUpCommands(CLI::App& app, Cli& cli);   ///< up, down, check
void AddTestCommand(CLI::App& app, Cli& cli);  ///< test (scenario files with expectations)
void AddStatusCommand(CLI::App& app, Cli& cli);
void AddFaultCommands(CLI::App& app, Cli& cli);
void AddIoCommands(CLI::App& app, Cli& cli);
void AddSdoCommands(CLI::App& app, Cli& cli);
void AddNmtCommands(CLI::App& app, Cli& cli);
void AddDumpCommand(CLI::App& app, Cli& cli);
void AddCaptureCommands(CLI::App& app, Cli& cli);
void AddTelemetryCommands(CLI::App& app, Cli& cli);  ///< top, watch (DDS, not the control API)

/// Sends `request` to the orchestrator and returns its response; prints its notice (an old signal
/// name, an input its pin's configuration does not read) on stderr. Throws CommandError when it
/// cannot be reached or answers with an error, UsageError (exit 2) when it refuses the request as
/// a bad one (Response.bad_request: an unknown node or signal, a value out of range ...).
control::Response Call(const GlobalOptions& global, control::Request request);

/// `message` as JSON (json_output.cpp): protobuf's JSON mapping (field names as in the .proto, every
/// field even when zero, enums by name, bytes base64) except that every number is a JSON number,
/// 64-bit integers too; indented, or on one line.
std::string ToJson(const google::protobuf::Message& message, bool one_line = false);
/// Prints ToJson and a newline.
void PrintJson(const google::protobuf::Message& message, bool one_line = false);

/// Prints Done.detail, or `fallback` when the orchestrator gave none.
void PrintDone(const control::Response& response, const std::string& fallback);

/// Hexadecimal numbers as CANopen writes them: "0x1017", "1017h" (any case). A bare number is
/// refused as ambiguous. Throws UsageError naming `what`.
std::uint32_t ParseHex(std::string_view text, std::string_view what, std::uint32_t max);
/// Decimal, "0x1F" or "1Fh". Throws UsageError naming `what`.
std::uint32_t ParseNumber(std::string_view text, std::string_view what, std::uint32_t max);

// CLI11 validators: refuse at parse time (exit 2) what the parsers above would.
CLI::Validator HexValidator(std::uint32_t max);
CLI::Validator NumberValidator(std::uint32_t max);
CLI::Validator DurationValidator();

/// A duration option's value in ms, for a uint32 *_ms field (validated by DurationValidator).
std::uint32_t DurationMs(const std::string& text);

}  // namespace canfleet::cli
