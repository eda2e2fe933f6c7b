// canfleet sdo read NODE INDEX SUB [TYPE], canfleet sdo write NODE INDEX SUB TYPE VALUE
#include <cctype>
#include <iostream>
#include <memory>

#include "orchestrator/control/sdo_value.hpp"
#include "tools/canfleet/cli.hpp"
#include "tools/canfleet/text_format.hpp"

namespace canfleet::cli {

namespace {

struct SdoArgs {
  std::string node;
  std::string index;
  std::string subindex;
  std::string type;
  std::string value;
  bool block = false;
  std::string port;  ///< "1", "2", "CAN1", "CAN2"; empty: CAN1
  bool json = false;
};

/// --port as the manuals print the ports (CAN1, CAN2): 1-based, or CANn. 0 was the first port
/// before; it is refused rather than guessed.
std::string PortError(const std::string& text) {
  std::string digits = text;
  if (digits.size() > 3 && (digits.rfind("CAN", 0) == 0 || digits.rfind("can", 0) == 0))
    digits = digits.substr(3);
  if (digits == "0")
    return "--port " + text +
           ": ports are numbered as the manuals print them, CAN1 and CAN2 (--port 1, --port CAN2); 0 no "
           "longer "
           "means the first port";
  if (digits.empty() || digits.size() > 2 || digits.find_first_not_of("0123456789") != std::string::npos)
    return "--port " + text + ": a CAN port, 1, 2, CAN1 or CAN2";
  return {};
}

/// The control API's 0-based port of a valid --port.
std::uint32_t PortIndex(const std::string& text) {
  if (text.empty()) return 0;
  const std::string digits =
      text.size() > 3 && !std::isdigit(static_cast<unsigned char>(text[0])) ? text.substr(3) : text;
  return static_cast<std::uint32_t>(std::stoul(digits) - 1);
}

CLI::Validator TypeValidator() {
  const std::string names(control::SdoTypeNames());
  return CLI::Validator(
      [names](std::string& s) {
        return control::ParseSdoType(s) ? std::string() : "unknown SDO type \"" + s + "\" (" + names + ")";
      },
      "TYPE");
}

void AddAddress(CLI::App& cmd, SdoArgs& a) {
  cmd.add_option("NODE", a.node, "Node name")->required();
  cmd.add_option("INDEX", a.index, "Object index in hex: 0x1017 or 1017h")
      ->required()
      ->check(HexValidator(0xFFFF));
  cmd.add_option("SUB", a.subindex, "Sub-index: 0, 0x01 or 01h")->required()->check(NumberValidator(0xFF));
}

void AddTransferOptions(CLI::App& cmd, SdoArgs& a) {
  cmd.add_flag("--block", a.block, "Use an SDO block transfer");
  cmd.add_option("--port", a.port, "CAN port of a multi-port node, as the manual prints it: 1, 2, CAN1, CAN2")
      ->check(CLI::Validator([](std::string& s) { return PortError(s); }, "CAN1|CAN2"));
}

int RunRead(const GlobalOptions& global, const SdoArgs& a) {
  control::Request request;
  auto* body = request.mutable_sdo_read();
  body->set_node(a.node);
  body->set_index(ParseHex(a.index, "INDEX", 0xFFFF));
  body->set_subindex(ParseNumber(a.subindex, "SUB", 0xFF));
  body->set_type(a.type);
  body->set_block(a.block);
  body->set_port(PortIndex(a.port));
  const control::Response response = Call(global, request);
  if (a.json)
    PrintJson(response.sdo());
  else
    std::cout << FormatSdoData(response.sdo());
  return kExitOk;
}

int RunWrite(const GlobalOptions& global, const SdoArgs& a) {
  control::Request request;
  auto* body = request.mutable_sdo_write();
  body->set_node(a.node);
  body->set_index(ParseHex(a.index, "INDEX", 0xFFFF));
  body->set_subindex(ParseNumber(a.subindex, "SUB", 0xFF));
  body->set_type(a.type);
  body->set_value(a.value);
  body->set_block(a.block);
  body->set_port(PortIndex(a.port));
  try {
    control::EncodeSdoValue(a.type, a.value);  // refuse a bad value before the orchestrator
  } catch (const control::SdoValueError& e) {
    throw UsageError(e.what());
  }
  PrintDone(Call(global, request), "ok");
  return kExitOk;
}

}  // namespace

void AddSdoCommands(CLI::App& app, Cli& cli) {
  CLI::App* sdo = app.add_subcommand("sdo", "Read and write a node's object dictionary");
  sdo->footer("Types (as cocomm names them): " + std::string(control::SdoTypeNames()) +
              "\nThe orchestrator is the SDO client, on its own port of the node's bus.");
  sdo->require_subcommand(1);

  auto r = std::make_shared<SdoArgs>();
  CLI::App* read = sdo->add_subcommand("read", "Upload an object and print its value");
  AddAddress(*read, *r);
  read->add_option("TYPE", r->type, "How to show the value (default: hex bytes)")->check(TypeValidator());
  AddTransferOptions(*read, *r);
  read->add_flag("--json", r->json, "Print the SdoData message as JSON (data in base64)");
  read->callback([&cli, r] { cli.action = [&cli, r] { return RunRead(cli.global, *r); }; });

  auto w = std::make_shared<SdoArgs>();
  CLI::App* write = sdo->add_subcommand("write", "Download a value to an object");
  AddAddress(*write, *w);
  write->add_option("TYPE", w->type, "The object's type")->required()->check(TypeValidator());
  write->add_option("VALUE", w->value, "1000, 0x3E8, -5, 1.5, true, hello, \"0a 0b 0c\" (os, d)")->required();
  AddTransferOptions(*write, *w);
  write->callback([&cli, w] { cli.action = [&cli, w] { return RunWrite(cli.global, *w); }; });
}

}  // namespace canfleet::cli
