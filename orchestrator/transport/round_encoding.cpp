#include "orchestrator/transport/round_encoding.hpp"

#include "bus/wire/byte_buffer.hpp"
#include "bus/wire/frame_record.hpp"

namespace canfleet::transport {

namespace {

struct RoundEncoding {
  std::uint64_t round = 0;  ///< SharedRound::Id, never 0
  wire::ByteBuffer records;
};

}  // namespace

const std::uint8_t* SharedRecords(const broker::SharedRound& round) {
  thread_local RoundEncoding cache;
  if (cache.round != round.Id()) {
    const auto frames = round.Frames();
    cache.records.clear();
    std::uint8_t* out = cache.records.Extend(frames.size() * wire::kFrameRecordSize);
    for (const broker::TimedFrame& f : frames) {
      wire::EncodeRecord(f.frame, f.time, out);
      out += wire::kFrameRecordSize;
    }
    cache.round = round.Id();
  }
  return cache.records.data();
}

}  // namespace canfleet::transport
