// Fuzzes the socketcand command path with arbitrary client bytes: ElementReader framing (fed in
// two pieces, split where the first byte says) and ParseCommand. Nothing may crash or grow
// without bound, and what parses must hold: a parsed frame is valid and survives
// FormatSend -> ParseCommand unchanged, and the server's formatting of it is well-formed.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "orchestrator/socketcand/protocol.hpp"

using namespace canfleet;
using namespace canfleet::socketcand;

namespace {

[[noreturn]] void Abort(const char* what, std::string_view detail) {
  std::fprintf(stderr, "socketcand_parser fuzz: %s: '%.*s'\n", what, static_cast<int>(detail.size()),
               detail.data());
  std::abort();
}

void Check(std::string_view element) {
  if (element.size() > kMaxElementLength) Abort("element longer than the limit", element);
  if (element.front() != '<' || element.back() != '>') Abort("element not framed by < >", element);
  const Command c = ParseCommand(element);
  if (c.kind != CommandKind::kSend && c.kind != CommandKind::kSendRtr) return;
  if (!c.frame.valid()) Abort("parsed an invalid frame", element);
  if (c.frame.remote() != (c.kind == CommandKind::kSendRtr))
    Abort("remote flag differs from the command", element);
  const std::string again = FormatSend(c.frame);
  const Command reparsed = ParseCommand(again);
  if (reparsed.kind != c.kind || !(reparsed.frame == c.frame)) Abort("FormatSend does not round-trip", again);
  std::string out;
  AppendFrame(out, c.frame, WallTime(std::chrono::seconds(1700000000)), true);
  if (out.size() % kAlignedRecordSize != 0 || out.back() != '>') Abort("aligned record malformed", out);
}

void Drain(ElementReader& reader, bool& stopped) {
  while (!stopped) {
    const ElementReader::Result r = reader.Next();
    if (r.status == ElementReader::Status::kNeedMore) {
      if (reader.Buffered() > kMaxElementLength) Abort("reader keeps more than one element", "");
      return;
    }
    if (r.status == ElementReader::Status::kTooLong) {
      stopped = true;  // the session closes the connection here
      return;
    }
    Check(r.element);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  const std::size_t split = size == 0 ? 0 : data[0] % (size + 1);
  ElementReader reader;
  bool stopped = false;
  reader.Feed(all.substr(0, split));
  Drain(reader, stopped);
  if (!stopped) {
    reader.Feed(all.substr(split));
    Drain(reader, stopped);
  }
  return 0;
}
