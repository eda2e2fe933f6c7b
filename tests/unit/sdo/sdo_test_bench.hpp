#pragma once
/// @file A node with an SDO server on a loopback bus, a probe playing the client in candump
/// notation, and the object dictionary the SDO tests use.

#include <cstdint>
#include <string>

#include "bus/loopback_bus.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/od/object_dictionary.hpp"
#include "node/canopen/sdo/sdo_server.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::canopen::test {

/// Objects with every property an SDO abort code can come from.
inline void AddSdoTestObjects(ObjectDictionary& od, SdoAbort& veto) {
  od.AddVar(0x1000, "Device type", DataType::kUnsigned32, Access::kRo, EncodeLe<std::uint32_t>(0x000F0194));
  od.AddVar(0x1008, "Device name", DataType::kVisibleString, Access::kConst, ToBytes("canfleet server"));
  od.AddVar(0x1017, "Producer heartbeat time", DataType::kUnsigned16, Access::kRw,
            EncodeLe<std::uint16_t>(0));
  AddSdoServerObjects(od);
  od.AddVar(0x2000, "U8", DataType::kUnsigned8, Access::kRw, {0});
  auto& limited =
      od.AddVar(0x2001, "Limited", DataType::kUnsigned32, Access::kRw, EncodeLe<std::uint32_t>(100));
  limited.low_limit = EncodeLe<std::uint32_t>(10);
  limited.high_limit = EncodeLe<std::uint32_t>(1000);
  od.AddVar(0x2002, "Write only", DataType::kUnsigned32, Access::kWo, EncodeLe<std::uint32_t>(0));
  auto& vetoed = od.AddVar(0x2003, "Vetoed", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(0));
  vetoed.AddValidator([&veto](const SubObject&, std::span<const std::uint8_t>, Origin) { return veto; });
  od.AddVar(0x2004, "Domain", DataType::kDomain, Access::kRw, {});
  od.AddVar(0x2005, "Flag", DataType::kBoolean, Access::kRw, {0});
  od.AddVar(0x2006, "U64", DataType::kUnsigned64, Access::kRw, EncodeLe<std::uint64_t>(0));
  Object record;
  record.index = 0x2010;
  record.code = ObjectCode::kRecord;
  SubObject count;
  count.type = DataType::kUnsigned8;
  count.access = Access::kConst;
  count.default_value = {1};
  SubObject member;
  member.type = DataType::kUnsigned8;
  member.access = Access::kRw;
  member.default_value = {7};
  record.subs.emplace(0, count);
  record.subs.emplace(1, member);
  od.Add(record);
  auto& no_data = od.AddVar(0x2011, "No data", DataType::kUnsigned8, Access::kRo, {0});
  no_data.AddReadHook([](SubObject&, Origin) { return SdoAbort::kNoData; });
}

/// Node 5 (request 605h, response 585h) with an SDO server and a probe on the same loopback bus.
struct ServerBench {
  explicit ServerBench(SdoServerOptions options = {}) : server(od, port, scheduler, options) {
    AddSdoTestObjects(od, veto);
    port.OnReceive([this](const CanFrame& frame, BusTime) { server.OnFrame(frame); });
    server.SetNodeId(5);
  }

  SdoAbort veto = SdoAbort::kNone;  ///< what the validator of 2003h answers
  ObjectDictionary od;
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& port = bus.Attach("node");
  canfleet::test::BusProbe probe{bus, "client"};
  SdoServer server;
};

}  // namespace canfleet::canopen::test
