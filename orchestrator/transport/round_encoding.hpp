#pragma once
/// @file The wire encoding of a broker round, made once for every session that delivers it
/// (issue 4: the records a frame becomes are the same for every receiver).

#include <cstdint>

#include "orchestrator/broker/port_sink.hpp"

namespace canfleet::transport {

/// The records (wire::EncodeRecord, wire::kFrameRecordSize bytes each) of every frame of
/// `round`, indexed like round.Frames(). Encoded on the first call for a round (SharedRound::Id);
/// later calls for the same round return the same bytes. One cache per thread: valid until the
/// next call for another round on this thread.
const std::uint8_t* SharedRecords(const broker::SharedRound& round);

}  // namespace canfleet::transport
