// Fuzzes what canfleet web writes and reads that is its own (web/): the page's JSON (WebState) from
// telemetry samples whose strings and numbers are anything a publisher on the domain could send,
// and `--listen`. Whatever the input: no crash, no exception but the documented invalid_argument,
// and every JSON message parses (protobuf's JSON parser into a Struct) with the node's name intact.
//
// Input: fields separated by NUL bytes: node name, device, signal name, unit, text, bus, then the
// rest as a --listen text; byte 0 also gives the node-ID and byte 1 a number's bit pattern source.
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "web/run_web.hpp"
#include "web/web_state.hpp"

using namespace canfleet;

namespace {

[[noreturn]] void Abort(const char* what, const std::string& detail) {
  std::fprintf(stderr, "web_json fuzz: %s: %s\n", what, detail.c_str());
  std::abort();
}

std::vector<std::string> Fields(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> out(1);
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == 0 && out.size() < 7)
      out.emplace_back();
    else
      out.back().push_back(static_cast<char>(data[i]));
  }
  out.resize(7);
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 10) return 0;
  const auto f = Fields(data + 10, size - 10);
  double value = 0;
  std::memcpy(&value, data + 1, sizeof value);  // any bit pattern: NaN and infinities too
  const auto t0 = tools::WallTime(std::chrono::seconds(1'700'000'000));
  web::WebState state(t0);
  telemetry::NodeStatusSample status;
  status.bus = f[5];
  status.node_id = static_cast<std::uint8_t>(data[0] & 0x7F);
  status.name = f[0];
  status.device = f[1];
  state.Apply(status, {.source_time = t0});
  telemetry::IoSnapshotSample io;
  io.bus = f[5];
  io.node_id = status.node_id;
  io.inputs = {{.name = f[2], .value = value, .unit = f[3], .text = f[4]}};
  state.Apply(io, {.source_time = t0});
  telemetry::BusStatsSample bus;
  bus.bus = f[5];
  bus.mode = data[9] & 1 ? "virtual" : "real";
  bus.load_percent = static_cast<float>(value);
  bus.simulated_s = value;
  state.Apply(bus, {.source_time = t0});
  web::Cursor cursor;
  const std::string json = state.UpdateJson(cursor, t0);
  google::protobuf::Struct parsed;
  const auto ok = google::protobuf::util::JsonStringToMessage(json, &parsed);
  if (!ok.ok()) Abort("not JSON", ok.message().as_string() + "\n" + json);
  const auto& nodes = parsed.fields().at("nodes").list_value();
  if (nodes.values_size() != 1) Abort("nodes", json);
  // A name goes through as it came when it is UTF-8 (the page shows what the publisher sent);
  // otherwise with U+FFFD for what is not.
  const std::string& name = nodes.values(0).struct_value().fields().at("name").string_value();
  if (name != web::ValidUtf8(f[0])) Abort("name", name + " vs " + f[0]);
  try {
    (void)web::ParseListen(f[6]);
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
