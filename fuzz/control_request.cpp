// Fuzzes what the control API reads from a client (orchestrator/control): the length-delimited
// framing (DelimitedReader, fed in reads of the size byte 0 picks) and the Request messages it
// yields, then the text the orchestrator parses out of a request before acting on it (an SDO
// write's type and value, a fault's summary). Whatever a client sends: no crash, no hang, no
// exception but the documented SdoValueError, and
//  - the split into reads never changes the outcome (same messages, same verdict);
//  - every message read survives AppendDelimited -> DelimitedReader unchanged;
//  - an SDO value that encodes is formatted back without an error, in the size of its type.
//
// Input: byte 0 picks the read size (1..64 bytes); the rest is the stream.
#include <google/protobuf/stubs/logging.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

#include "orchestrator/control/control_protocol.hpp"
#include "orchestrator/control/fault_text.hpp"
#include "orchestrator/control/sdo_value.hpp"

using namespace canfleet::control;

namespace {

/// Small enough that the fuzzer reaches the size limit, large enough for real requests.
constexpr std::size_t kMaxMessage = 4096;

[[noreturn]] void Abort(const char* what, const std::string& detail) {
  std::fprintf(stderr, "control_request fuzz: %s: %s\n", what, detail.c_str());
  std::abort();
}

struct Outcome {
  std::vector<std::string> messages;  ///< each request serialised (deterministic for one schema)
  bool failed = false;
};

Outcome Read(std::span<const std::uint8_t> stream, std::size_t chunk) {
  Outcome out;
  DelimitedReader reader(kMaxMessage);
  Request request;
  for (std::size_t at = 0; at < stream.size() && !out.failed; at += chunk) {
    reader.Append(stream.subspan(at, std::min(chunk, stream.size() - at)));
    for (;;) {
      const auto r = reader.Next(request);
      if (r == DelimitedReader::Result::kError) {
        if (reader.Error().empty()) Abort("an error without a reason", "");
        out.failed = true;
        break;
      }
      if (r == DelimitedReader::Result::kNeedMore) break;
      out.messages.push_back(request.SerializeAsString());
      if (out.messages.back().size() > kMaxMessage) Abort("a message over the limit was read", "");
    }
  }
  return out;
}

void CheckRoundTrip(const std::string& serialized) {
  Request request;
  if (!request.ParseFromString(serialized)) Abort("a message read does not parse again", "");
  std::string framed;
  if (!AppendDelimited(request, framed, kMaxMessage)) return;  // unknown fields may grow it
  DelimitedReader reader(kMaxMessage);
  reader.Append(framed.data(), framed.size());
  Request again;
  if (reader.Next(again) != DelimitedReader::Result::kMessage)
    Abort("a framed message does not read back", reader.Error());
  if (again.SerializeAsString() != serialized) Abort("a message reads back differently", "");
}

void CheckSdoWrite(const SdoWrite& write) {
  std::vector<std::uint8_t> bytes;
  try {
    bytes = EncodeSdoValue(write.type(), write.value());
  } catch (const SdoValueError&) {
    return;  // the request is refused with this message
  }
  const auto type = ParseSdoType(write.type());
  if (!type) Abort("a value encoded for an unknown type", write.type());
  const std::size_t size = SdoTypeSize(*type);
  if (size != 0 && bytes.size() != size) Abort("an encoded value has the wrong size", write.type());
  try {
    (void)FormatSdoValue(*type, bytes);
  } catch (const SdoValueError& e) {
    Abort("an encoded value cannot be formatted", e.what());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool quiet = [] {
    google::protobuf::SetLogHandler(nullptr);  // rejected UTF-8 in a string field is expected here
    return true;
  }();
  (void)quiet;
  if (size < 1) return 0;
  const std::size_t chunk = 1 + data[0] % 64;
  const std::span<const std::uint8_t> stream(data + 1, size - 1);

  const Outcome split = Read(stream, chunk);
  const Outcome whole = Read(stream, stream.size() + 1);
  if (split.failed != whole.failed || split.messages != whole.messages)
    Abort("the split into reads changed the outcome", std::to_string(chunk));

  for (const auto& serialized : whole.messages) {
    CheckRoundTrip(serialized);
    Request request;
    request.ParseFromString(serialized);
    if (request.has_sdo_write()) CheckSdoWrite(request.sdo_write());
    if (request.has_fault_inject()) (void)SummarizeFault(request.fault_inject());
  }
  return 0;
}
