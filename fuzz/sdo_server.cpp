// Fuzzes the SDO server (CiA 301 §7.2.4) with sequences of frames, time steps and enable/node-ID
// changes. Whatever came before, the server must answer only with 8-byte frames on its response
// COB-ID, and afterwards a valid expedited upload must succeed — at once, or after the SDO timeout
// when the sequence left it inside a block download sub-block, where a request reads as a segment.
//
// Input: byte 0 picks the server's block size; then records of 10 bytes:
//   [op] [len/flags] [d0..d7]
//   op % 8 = 0..4  send a frame: DLC = len & 0x0F (above 8: 8), remote if len & 0x10,
//                  to another node's COB-ID (606h, must be ignored) if len & 0x20
//   op % 8 = 5     advance simulated time by d0 × 8 ms
//   op % 8 = 6     SetEnabled(d0 & 1)
//   op % 8 = 7     SetNodeId(5) again (aborts a transfer in progress)
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "bus/loopback_bus.hpp"
#include "clock/scheduler.hpp"
#include "node/canopen/od/object_dictionary.hpp"
#include "node/canopen/sdo/sdo_server.hpp"

using namespace canfleet;
using namespace canfleet::canopen;
using namespace std::chrono_literals;

namespace {

void AddObjects(ObjectDictionary& od) {
  od.AddVar(0x1000, "Device type", DataType::kUnsigned32, Access::kRo, EncodeLe<std::uint32_t>(0x000F0194));
  od.AddVar(0x1008, "Device name", DataType::kVisibleString, Access::kConst, ToBytes("canfleet fuzz node"));
  od.AddVar(0x1017, "Heartbeat", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(0));
  AddSdoServerObjects(od);
  auto& limited =
      od.AddVar(0x2001, "Limited", DataType::kUnsigned32, Access::kRw, EncodeLe<std::uint32_t>(100));
  limited.low_limit = EncodeLe<std::uint32_t>(10);
  limited.high_limit = EncodeLe<std::uint32_t>(1000);
  od.AddVar(0x2002, "Write only", DataType::kUnsigned32, Access::kWo, EncodeLe<std::uint32_t>(0));
  auto& vetoed = od.AddVar(0x2003, "Vetoed", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(0));
  vetoed.AddValidator([](const SubObject&, std::span<const std::uint8_t> data, Origin) {
    return !data.empty() && data[0] == 0x22 ? SdoAbort::kDeviceState : SdoAbort::kNone;
  });
  od.AddVar(0x2004, "Domain", DataType::kDomain, Access::kRw, Bytes(300, 0x5A));
  od.AddVar(0x2005, "Flag", DataType::kBoolean, Access::kRw, {0});
  od.AddVar(0x2006, "U64", DataType::kUnsigned64, Access::kRw, EncodeLe<std::uint64_t>(0));
}

CanFrame Request(std::initializer_list<std::uint8_t> bytes) {
  return CanFrame::Data(0x605, bytes);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ObjectDictionary od;
  AddObjects(od);
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& node = bus.Attach("node");
  LoopbackPort& client = bus.Attach("client");
  SdoServerOptions options;
  options.max_transfer_bytes = 4096;
  options.block_size = size > 0 ? static_cast<std::uint8_t>(1 + data[0] % 127) : 127;
  SdoServer server(od, node, scheduler, options);
  node.OnReceive([&](const CanFrame& f, BusTime) { server.OnFrame(f); });
  std::vector<CanFrame> responses;
  client.OnReceive([&](const CanFrame& f, BusTime) {
    // Only full SDO frames from 585h, and never an undefined server command specifier (7).
    if (f.id != 0x585 || f.dlc != 8 || f.flags != 0 || (f.data[0] >> 5) == 7) std::abort();
    responses.push_back(f);
  });
  server.SetNodeId(5);

  for (std::size_t at = 1; at + 10 <= size; at += 10) {
    const std::uint8_t* rec = data + at;
    switch (rec[0] % 8) {
      case 5:
        scheduler.Advance(std::chrono::milliseconds(rec[2] * 8));
        break;
      case 6:
        server.SetEnabled(rec[2] & 1);
        break;
      case 7:
        server.SetNodeId(5);
        break;
      default: {
        CanFrame f;
        f.id = (rec[1] & 0x20) ? 0x606 : 0x605;
        f.dlc = static_cast<std::uint8_t>(std::min(rec[1] & 0x0F, 8));
        if (rec[1] & 0x10) f.flags = CanFrame::kRemote;
        for (int i = 0; i < 8; ++i)
          f.data[i] = rec[2 + i];
        const std::size_t before = responses.size();
        client.Send(f);
        if (f.id == 0x606 && responses.size() != before) std::abort();  // another node's request
        break;
      }
    }
  }

  // The server is not wedged: a valid upload of 1000h succeeds.
  server.SetEnabled(true);
  const CanFrame expected = CanFrame::Data(0x585, {0x43, 0x00, 0x10, 0x00, 0x94, 0x01, 0x0F, 0x00});
  responses.clear();
  client.Send(Request({0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}));
  if (responses.size() == 1 && responses[0] == expected) return 0;
  scheduler.Advance(options.timeout);
  responses.clear();
  client.Send(Request({0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}));
  if (responses.size() != 1 || !(responses[0] == expected)) std::abort();
  return 0;
}
