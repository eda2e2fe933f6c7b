// Fuzzes the node <-> broker stream decoder (bus/wire/stream_decoder.hpp) with arbitrary bytes
// split into arbitrary reads. Whatever arrives: no crash, no hang, every frame handed out is
// valid, and the split never changes the outcome (same messages, same verdict) — a read boundary
// is not something a peer controls reliably, so it must not matter.
//
// Input: byte 0 picks the read size (1..64 bytes); the rest is the stream.
#include <google/protobuf/stubs/logging.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

#include "bus/wire/message_writer.hpp"
#include "bus/wire/stream_decoder.hpp"

using namespace canfleet;
using namespace canfleet::wire;

namespace {

struct Outcome {
  std::vector<std::string> messages;
  bool failed = false;
};

/// A message as bytes that identify it: type, then the frames re-encoded by MessageWriter (so
/// the comparison also checks that every decoded frame encodes again) or the envelope.
std::string Fingerprint(const Message& m) {
  std::string out(1, static_cast<char>(m.type));
  switch (m.type) {
    case MessageType::kFrames:
    case MessageType::kTxConfirm: {
      MessageWriter again;
      for (std::size_t i = 0; i < m.frames.size(); ++i) {
        const StampedFrame f = m.frames[i];
        if (!f.frame.valid()) std::abort();  // the decoder validated every record
        again.AddFrame(f.frame, f.time);
      }
      const auto bytes = again.Bytes();
      out.append(bytes.begin(), bytes.end());
      break;
    }
    case MessageType::kControllerEvent:
      out += std::to_string(static_cast<int>(m.controller.state)) + "/" + std::to_string(m.controller.tec) +
             "/" + std::to_string(m.controller.rec);
      break;
    default:
      out += m.envelope.SerializeAsString();
      break;
  }
  return out;
}

Outcome Decode(std::span<const std::uint8_t> stream, std::size_t chunk, std::size_t max_message) {
  StreamDecoder decoder(max_message);
  Message message;
  Outcome out;
  for (std::size_t at = 0; at < stream.size(); at += chunk) {
    const std::size_t n = std::min(chunk, stream.size() - at);
    // Half the reads through WritableSpace/Commit (as a socket does), half through Feed.
    if ((at / chunk) % 2 == 0) {
      auto space = decoder.WritableSpace(n);
      if (space.size() < n) std::abort();
      std::copy_n(stream.begin() + static_cast<std::ptrdiff_t>(at), n, space.begin());
      decoder.Commit(n);
    } else {
      decoder.Feed(stream.subspan(at, n));
    }
    for (;;) {
      const auto result = decoder.Next(message);
      if (result == StreamDecoder::Result::kNeedMore) break;
      if (result == StreamDecoder::Result::kError) {
        if (decoder.Error().empty()) std::abort();
        out.failed = true;
        return out;
      }
      out.messages.push_back(Fingerprint(message));
    }
  }
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  google::protobuf::SetLogHandler(nullptr);  // rejected UTF-8 in a Hello is expected here
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::size_t chunk = 1 + data[0] % 64;
  const std::span<const std::uint8_t> stream(data + 1, size - 1);

  const Outcome whole = Decode(stream, stream.empty() ? 1 : stream.size(), kMaxMessageSize);
  const Outcome split = Decode(stream, chunk, kMaxMessageSize);
  if (whole.failed != split.failed || whole.messages != split.messages) std::abort();
  // A small limit reaches the "too large" path with short inputs.
  (void)Decode(stream, chunk, 48);
  return 0;
}
