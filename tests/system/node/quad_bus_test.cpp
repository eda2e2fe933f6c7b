// Two Quad controllers on one virtual bus, in three processes (issue 5: "a multi-process test
// (broker + two nodes, e.g. one Quad driven by a second node's TPDO) showing a simulated input
// moving an output across the bus").
//
// canfleet-broker, canfleet-node --device quad-controller --node-id 5 and --node-id 6; the test is
// the master (BrokerClientPort + SdoClient in this process). It configures node 6 by SDO, as a
// master would, so that node 6's RPDO1 consumes node 5's TPDO1, starts both nodes, moves node 5's
// simulated AIN1 through node 5's --stdin-control and reads node 6's POUT1 through node 6's.
// Citations are to the AX020506 user manual V2.02.
#include <gtest/gtest.h>

#include "tests/system/node/node_system_support.hpp"

namespace canfleet::system_test {
namespace {

using namespace std::chrono_literals;
using canopen::SdoAbort;

std::vector<std::string> QuadArgs(int node_id, const std::string& endpoint) {
  return {"--device", "quad-controller", "--node-id", std::to_string(node_id), "--bus", "can0@" + endpoint};
}

TEST(CanfleetNodeQuadBus, AnInputOfNode5MovesAnOutputOfNode6AcrossTheBus) {
  TempDir dir;
  BrokerProcess broker(dir, "tcp://127.0.0.1:0");
  ASSERT_FALSE(broker.endpoint().empty());
  BusMaster master(broker.endpoint());
  ASSERT_TRUE(master.WaitConnected()) << broker.Log();

  NodeProcess node5(dir, "node5", QuadArgs(5, broker.endpoint()));
  NodeProcess node6(dir, "node6", QuadArgs(6, broker.endpoint()));
  // CiA 301 §7.2.8.3.3: each node says it booted (manual §4.2: into pre-operational, 5555h = 0).
  ASSERT_TRUE(master.WaitForFrame("705#00")) << node5.Output();
  ASSERT_TRUE(master.WaitForFrame("706#00")) << node6.Output();

  // Node 6, configured by SDO in pre-operational (manual §3.1.1: "All PDOs are dynamically
  // mappable"; CiA 301 §7.5.2.35-36 order: invalidate, clear the count, map, set the count,
  // validate with the new COB-ID).
  //  - RPDO1 (1400h/1600h, default 200h + node-ID mapping 7330h.1-4) takes node 5's TPDO1
  //    (180h + 5, mapping 7100h.1-4 = AIN1-4 field values in mV, manual §3.1.1, §3.3.12);
  //  - its first 16 bits go to 7330h.1 (AO Output Field Value POUT1 in mA, §3.5.20), so AIN1 of
  //    node 5 commands POUT1 of node 6; the other 6 bytes go to INTEGER16 dummy entries (the EDS's
  //    [DummyUsage] Dummy0003=1), so the mapping still covers the whole 8-byte frame (a shorter
  //    one would make every frame a CiA 301 "PDO length exceeded" error, 8220h).
  struct Step {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint64_t value;
    int size;
  };
  const std::vector<Step> configuration = {
      {0x1400, 1, 0x80000206, 4},  // RPDO1 not valid while it changes
      {0x1600, 0, 0, 1},           // no entries while they change
      {0x1600, 1, 0x73300110, 4},  // 7330h.1, 16 bits (AIN1)
      {0x1600, 2, 0x00030010, 4},  // dummy INTEGER16 (AIN2)
      {0x1600, 3, 0x00030010, 4},  // dummy INTEGER16 (AIN3)
      {0x1600, 4, 0x00030010, 4},  // dummy INTEGER16 (AIN4)
      {0x1600, 0, 4, 1},           // four entries
      {0x1400, 1, 0x00000185, 4},  // valid, on node 5's TPDO1 COB-ID
      {0x6310, 1, 20, 2},          // §3.5.15: POUT1 is a current output (20, the default)
      {0x3010, 1, 0, 1},           // §3.5.1: POUT1 controlled by the CANopen message (0, the default)
      {0x30A0, 1, 2, 1},           // §3.5.10: ramps unless the control is CAN (2, the default)
  };
  for (const Step& s : configuration) {
    EXPECT_EQ(master.Write(6, s.index, s.sub, s.value, s.size), SdoAbort::kNone)
        << std::hex << s.index << "." << int{s.sub} << " = " << s.value;
  }
  EXPECT_EQ(master.ReadUnsigned(6, 0x1400, 1), 0x185u);
  EXPECT_EQ(master.ReadUnsigned(6, 0x1600, 1), 0x73300110u);
  EXPECT_EQ(master.ReadUnsigned(6, 0x1600, 2), 0x00030010u);

  // The first input value, set on node 5's pins (its simulated AIN1).
  EXPECT_EQ(node5.Set("IN1.voltage_mV", "1200"), "ok");
  EXPECT_EQ(node6.GetNumber("OUT1.current_mA"), 0.0);  // §4.2: pre-operational, no PDOs yet

  // CiA 301 §7.2.8.3.1: NMT start, all nodes. PDOs run in operational only.
  ASSERT_TRUE(master.Nmt(BusMaster::kNmtStart, 0));
  const std::size_t started = master.Frames().size();

  // Node 5's TPDO1 carries AIN1 = 1200 mV (04B0h) every 100 ms (§3.1.1: type 254, event timer 100).
  ASSERT_TRUE(master.WaitForFrame([](const SeenFrame& f) { return f.text.starts_with("185#B004"); }, started))
      << node5.Output();
  // Node 6's POUT1 follows: 1200 mA (§3.5.20 field value in mA; 30A0h = 2: no ramp under CAN).
  EXPECT_TRUE(master.RunUntil([&] { return node6.GetNumber("OUT1.current_mA") == 1200.0; }))
      << "POUT1 of node 6: " << node6.Get("OUT1.current_mA").value_or("?") << "\n"
      << node6.Output();
  // ... and says so on the bus: TPDO4 (480h + 6) maps 30C0h.1, the measured current (§3.5.12).
  EXPECT_TRUE(
      master.WaitForFrame([](const SeenFrame& f) { return f.text.starts_with("486#B004"); }, started));

  // The input moves again, the output follows again.
  EXPECT_EQ(node5.Set("IN1.voltage_mV", "1800"), "ok");
  EXPECT_TRUE(master.RunUntil([&] { return node6.GetNumber("OUT1.current_mA") == 1800.0; }))
      << "POUT1 of node 6: " << node6.Get("OUT1.current_mA").value_or("?") << "\n"
      << node6.Output();
  EXPECT_EQ(master.ReadUnsigned(6, 0x7330, 1), 1800u);  // what the RPDO wrote
  EXPECT_EQ(master.ReadUnsigned(6, 0x30C0, 1), 1800u);  // what flows

  // §4.2 again: back in pre-operational, the CAN-controlled output of node 6 switches off.
  ASSERT_TRUE(master.Nmt(BusMaster::kNmtPreOperational, 6));
  EXPECT_TRUE(master.RunUntil([&] { return node6.GetNumber("OUT1.current_mA") == 0.0; })) << node6.Output();

  // Nothing went wrong on the way (§4.1: no EMCY from either node).
  for (const auto& f : master.Frames())
    EXPECT_FALSE(f.text.starts_with("085#") || f.text.starts_with("086#")) << "EMCY " << f.text;
  EXPECT_TRUE(node5.process().Running()) << node5.Output();
  EXPECT_TRUE(node6.process().Running()) << node6.Output();
}

}  // namespace
}  // namespace canfleet::system_test
