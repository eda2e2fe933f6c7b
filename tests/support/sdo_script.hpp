#pragma once
/// @file The master's side of a device unit test as frame scripts (candump notation, as BusProbe
/// speaks it): SDO expedited requests and answers for one node (CiA 301 §7.2.4.3), and a master that
/// sets aside the frames an SDO exchange crosses so that a test still sees them in order. Every
/// product fixture (Quad, valve, encoder, power supply) uses these with its own node-ID.

#include <cstdint>
#include <deque>
#include <string>
#include <string_view>
#include <vector>

#include "tests/support/bus_probe.hpp"

namespace canfleet::test {

/// Little-endian hex of the low `size` bytes of `value` ("E803" for 1000, 2 bytes).
std::string LeHex(std::uint64_t value, int size);

/// Expedited download request to `node` ("605#2B" + index + sub + data, `size` 1..4 bytes).
std::string SdoDownload(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint64_t value,
                        int size);
/// The download confirmation from `node` ("585#60" + index + sub + 00000000).
std::string SdoDownloaded(std::uint8_t node, std::uint16_t index, std::uint8_t sub);
/// An abort from `node` with `code`.
std::string SdoAbortFrom(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t code);
/// Upload request to `node` ("605#40" + index + sub + 00000000).
std::string SdoUpload(std::uint8_t node, std::uint16_t index, std::uint8_t sub);

/// Every frame since the last call: those an SDO exchange set aside in `backlog` first, then the
/// probe's.
std::vector<std::string> TakeFrames(BusProbe& probe, std::deque<std::string>& backlog);
/// Of TakeFrames, those starting with `prefix` ("085#" for node 5's EMCY).
std::vector<std::string> TakeFrames(BusProbe& probe, std::deque<std::string>& backlog,
                                    std::string_view prefix);
/// Sends `request` and returns `node`'s SDO answer ("" if none); every other frame received before
/// or with it goes to `backlog`.
std::string ExchangeSdo(BusProbe& probe, std::deque<std::string>& backlog, std::uint8_t node,
                        std::string_view request);
/// The value of an expedited upload answer ("585#4B..." 1 to 4 bytes), sign-extended if
/// `is_signed`; 0 with a test failure when `answer` is not one.
std::int64_t ExpeditedValue(const std::string& answer, bool is_signed);

}  // namespace canfleet::test
