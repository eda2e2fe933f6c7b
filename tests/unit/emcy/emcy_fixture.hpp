#pragma once
// A node with the EMCY objects on a loopback bus, on simulated time, for the EMCY tests.

#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bus/loopback_bus.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/emcy/emcy.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::canopen {

using namespace std::chrono_literals;

inline ErrorEntry Error(std::uint16_t code, std::uint16_t info = 0, std::uint8_t bits = kErrorRegisterGeneric,
                        std::array<std::uint8_t, 5> msef = {}) {
  ErrorEntry e;
  e.code = code;
  e.info = info;
  e.register_bits = bits;
  e.msef = msef;
  return e;
}

class EmcyTest : public ::testing::Test {
 protected:
  EmcyTest() {
    recorder_.OnReceive([this](const CanFrame& f, BusTime) {
      timed.emplace_back(scheduler.Now().time_since_epoch(), ToCandump(f));
    });
  }

  /// Adds the CiA 301 objects (1003h `entries` deep) with node 5's defaults, then starts node 5's
  /// EMCY producer in Pre-operational.
  Emcy& Start(EmcyOptions options = {}, std::uint8_t entries = 8) {
    AddEmcyObjects(od, entries);
    return StartOn(options);
  }

  /// Starts node 5's EMCY producer on whatever `od` holds.
  Emcy& StartOn(EmcyOptions options = {}) {
    od.RestoreDefaults(0x1000, 0x1FFF, 5);
    service.emplace(od, node, scheduler, options);
    service->SetNodeId(5);
    service->SetNmtState(NmtState::kPreOperational);
    return *service;
  }

  std::uint64_t Get(std::uint16_t index, std::uint8_t sub = 0) const { return od.GetUnsigned(index, sub); }

  /// 1003h as an SDO client reads it: sub-index 0, then sub-indexes 1..count.
  std::vector<std::uint32_t> ErrorField() {
    Bytes out;
    EXPECT_EQ(od.Read(0x1003, 0, out), SdoAbort::kNone);
    std::vector<std::uint32_t> entries;
    const auto count = DecodeUnsignedLe(out);
    for (std::uint64_t sub = 1; sub <= count; ++sub) {
      EXPECT_EQ(od.Read(0x1003, static_cast<std::uint8_t>(sub), out), SdoAbort::kNone);
      entries.push_back(static_cast<std::uint32_t>(DecodeUnsignedLe(out)));
    }
    return entries;
  }

  SdoAbort WriteU32(std::uint16_t index, std::uint32_t value) { return od.Write(index, 0, EncodeLe(value)); }
  SdoAbort WriteU16(std::uint16_t index, std::uint16_t value) { return od.Write(index, 0, EncodeLe(value)); }

  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& node = bus.Attach("node");
  test::BusProbe probe{bus};
  /// Every frame with the simulated time it went out at.
  std::vector<std::pair<Duration, std::string>> timed;
  ObjectDictionary od;
  std::optional<Emcy> service;

 private:
  LoopbackPort& recorder_ = bus.Attach("recorder");
};

using Timed = std::vector<std::pair<Duration, std::string>>;

}  // namespace canfleet::canopen
