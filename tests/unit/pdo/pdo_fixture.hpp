#pragma once
// Shared fixture of the PDO tests: a node (PdoService on a loopback port) with the default PDO
// records of AddPdoObjects(4, 4) for node-ID 5, a few application objects, a master probe and a
// recorder that stamps every frame with its simulated time.

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "node/canopen/pdo/pdo_service.hpp"
#include "node/canopen/sync/sync_objects.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::canopen::test_pdo {

using namespace std::chrono_literals;

/// Records communication errors as "RpdoTimeout(1)+" / "...-".
class RecordingErrors final : public CommErrorSink {
 public:
  void OnCommError(const CommError& error, bool active) override {
    events.push_back(Name(error.kind) + "(" + std::to_string(error.detail) + (active ? ")+" : ")-"));
  }
  static std::string Name(CommErrorKind kind) {
    switch (kind) {
      case CommErrorKind::kRpdoTimeout:
        return "RpdoTimeout";
      case CommErrorKind::kRpdoTooShort:
        return "RpdoTooShort";
      case CommErrorKind::kRpdoTooLong:
        return "RpdoTooLong";
      case CommErrorKind::kSyncLength:
        return "SyncLength";
      default:
        return "Other";
    }
  }
  std::vector<std::string> events;
};

/// "<time> <frame>" for every frame on the bus not sent by itself; time as "150ms" or "10500us".
class TimedRecorder {
 public:
  TimedRecorder(LoopbackBus& bus, const Scheduler& scheduler) : port_(bus.Attach("recorder")) {
    port_.OnReceive([this, &scheduler](const CanFrame& frame, BusTime) {
      frames_.push_back(Stamp(scheduler.Now()) + " " + ToCandump(frame));
    });
  }
  static std::string Stamp(TimePoint t) {
    auto us = std::chrono::duration_cast<std::chrono::microseconds>(t.time_since_epoch()).count();
    return us % 1000 == 0 ? std::to_string(us / 1000) + "ms" : std::to_string(us) + "us";
  }
  std::vector<std::string> Take() {
    auto out = std::move(frames_);
    frames_.clear();
    return out;
  }

 private:
  LoopbackPort& port_;
  std::vector<std::string> frames_;
};

using Frames = std::vector<std::string>;

class PdoTest : public ::testing::Test {
 protected:
  static constexpr std::uint8_t kNodeId = 5;

  PdoTest() {
    AddPdoObjects(od, 4, 4);
    AddSyncObjects(od, true);  // 1007h: the synchronous window
    // Shaped like the devices' CiA 401 objects: ARRAYs whose sub1.. are mappable.
    AddArray(0x6000, "DI read state 8 input lines", DataType::kUnsigned8, Access::kRo, 1);
    AddArray(0x6200, "DO write state 8 output lines", DataType::kUnsigned8, Access::kRw, 1);
    AddArray(0x7100, "AI input field value", DataType::kInteger16, Access::kRo, 4);
    AddArray(0x7300, "AO output process value", DataType::kInteger16, Access::kRw, 4);
    di = od.Find(0x6000, 1);
    do_ = od.Find(0x6200, 1);
    od.AddVar(0x2000, "Not mappable", DataType::kUnsigned32, Access::kRw, EncodeLe<std::uint32_t>(0));
    od.AddVar(0x2001, "Write-only", DataType::kUnsigned16, Access::kWo, EncodeLe<std::uint16_t>(0), true);
    for (std::uint16_t i = 0; i < 3; ++i) {
      flags[i] = &od.AddVar(static_cast<std::uint16_t>(0x2010 + i), "Flag", DataType::kBoolean, Access::kRw,
                            {0}, true);
    }
    od.AddVar(0x2020, "Text", DataType::kVisibleString, Access::kRw, ToBytes("abc"), true);
    od.AddVar(0x2030, "Counter64", DataType::kUnsigned64, Access::kRw, EncodeLe<std::uint64_t>(0), true);
    od.RestoreDefaults(0x1000, 0x1FFF, kNodeId);
  }

  void AddArray(std::uint16_t index, std::string name, DataType type, Access access, std::uint8_t subs) {
    Object array;
    array.index = index;
    array.name = std::move(name);
    array.code = ObjectCode::kArray;
    SubObject count;
    count.type = DataType::kUnsigned8;
    count.access = Access::kConst;
    count.default_value = {subs};
    array.subs.emplace(0, count);
    for (std::uint8_t i = 1; i <= subs; ++i) {
      SubObject value;
      value.type = type;
      value.access = access;
      value.pdo_mappable = true;
      value.default_value = Bytes(FixedSize(type).value_or(1), 0);
      array.subs.emplace(i, value);
    }
    od.Add(std::move(array));
  }

  /// Builds the service on the dictionary as it is now.
  void Start() {
    pdo = std::make_unique<PdoService>(od, node_port, scheduler, errors);
    node_port.OnReceive([this](const CanFrame& frame, BusTime) { consumed.push_back(pdo->OnFrame(frame)); });
  }

  SdoAbort W8(std::uint16_t index, std::uint8_t sub, std::uint8_t value) {
    return od.Write(index, sub, Bytes{value});
  }
  SdoAbort W16(std::uint16_t index, std::uint8_t sub, std::uint16_t value) {
    return od.Write(index, sub, EncodeLe<std::uint16_t>(value));
  }
  SdoAbort W32(std::uint16_t index, std::uint8_t sub, std::uint32_t value) {
    return od.Write(index, sub, EncodeLe<std::uint32_t>(value));
  }
  void Set(std::uint16_t index, std::uint8_t sub, std::int64_t value) {
    ASSERT_EQ(od.SetSigned(index, sub, value), SdoAbort::kNone);
  }

  struct PdoSetup {
    std::vector<std::uint32_t> entries;
    std::uint8_t type = 255;
    std::uint16_t event_timer_ms = 0;
    std::uint16_t inhibit_100us = 0;
    std::uint8_t sync_start = 0;
    std::uint32_t cob_id = 0;  ///< 0: keep the current CAN-ID (valid, no RTR)
  };

  /// Configures PDO `number` through SDO-origin writes, in the CiA 301 order: disable, sub0 = 0,
  /// entries, sub0 = n, parameters, enable.
  void Configure(bool transmit, std::size_t number, const PdoSetup& s) {
    const auto comm = static_cast<std::uint16_t>((transmit ? 0x1800 : 0x1400) + number - 1);
    const auto map = static_cast<std::uint16_t>(comm + 0x200);
    const auto current = static_cast<std::uint32_t>(od.GetUnsigned(comm, 1));
    ASSERT_EQ(W32(comm, 1, current | kPdoCobIdInvalid), SdoAbort::kNone);
    ASSERT_EQ(W8(map, 0, 0), SdoAbort::kNone);
    for (std::size_t i = 0; i < s.entries.size(); ++i) {
      ASSERT_EQ(W32(map, static_cast<std::uint8_t>(i + 1), s.entries[i]), SdoAbort::kNone) << i;
    }
    ASSERT_EQ(W8(map, 0, static_cast<std::uint8_t>(s.entries.size())), SdoAbort::kNone);
    const std::uint32_t cob = s.cob_id != 0 ? s.cob_id : ((current & ~kPdoCobIdInvalid) | kPdoCobIdNoRtr);
    ASSERT_EQ(W32(comm, 1, cob | kPdoCobIdInvalid), SdoAbort::kNone);
    ASSERT_EQ(W8(comm, 2, s.type), SdoAbort::kNone);
    ASSERT_EQ(W16(comm, 3, s.inhibit_100us), SdoAbort::kNone);
    ASSERT_EQ(W16(comm, 5, s.event_timer_ms), SdoAbort::kNone);
    if (transmit) {
      ASSERT_EQ(W8(comm, 6, s.sync_start), SdoAbort::kNone);
    }
    ASSERT_EQ(W32(comm, 1, cob & ~kPdoCobIdInvalid), SdoAbort::kNone);
  }
  void Tpdo(std::size_t number, const PdoSetup& s) { Configure(true, number, s); }
  void Rpdo(std::size_t number, const PdoSetup& s) { Configure(false, number, s); }

  void Operational() { pdo->SetNmtState(NmtState::kOperational); }

  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& node_port = bus.Attach("node");
  test::BusProbe master{bus, "master"};
  TimedRecorder recorder{bus, scheduler};
  ObjectDictionary od;
  RecordingErrors errors;
  std::unique_ptr<PdoService> pdo;
  std::vector<bool> consumed;
  SubObject* di = nullptr;
  SubObject* do_ = nullptr;
  SubObject* flags[3] = {};
};

}  // namespace canfleet::canopen::test_pdo
