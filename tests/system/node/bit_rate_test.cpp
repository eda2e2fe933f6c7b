// A node's bit rate takes effect on the bus (issue 15, point 5): canfleet-broker (can0 at
// 500 kbit/s) and two canfleet-node processes, valve-12in12out nodes 5 (A) and 6 (B), each
// consuming the other's heartbeat (CiA 301 §7.2.8.3.2). The test is the master (BrokerClientPort +
// SdoClient in this process). B is switched to 250 kbit/s, by LSS (CiA 305 §8.3.2 "configure bit
// timing parameters" / "activate bit timing parameters", the steps of UMAX020411A §3.1.1.2) or by
// its 5B50h "Change Baud Rate" (§3.4.110) stored with 1010h (§3.2.x "Store Parameters") and an NMT
// reset node. At the wrong rate B exchanges no frames with the bus (orchestrator/broker/README.md
// "Bit rate"): A's consumer of B raises heartbeat loss (EMCY 8130h, §3.2.4 Table 33), B's consumer
// of A does too, B sees error frames and its own heartbeats are destroyed (error frames on 706h).
// Set back to 500 kbit/s by a master that meets B at its rate, B is normal again.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "node/canopen/lss/lss_protocol.hpp"
#include "tests/system/node/node_system_support.hpp"

namespace canfleet::system_test {
namespace {

using namespace std::chrono_literals;
using canopen::SdoAbort;

constexpr std::uint8_t kA = 5;
constexpr std::uint8_t kB = 6;

std::vector<std::string> ValveArgs(std::uint8_t node_id, const std::string& endpoint,
                                   const std::string& state_dir) {
  return {"--device",    "valve-12in12out",
          "--node-id",   std::to_string(node_id),
          "--serial",    std::to_string(1000 + node_id),
          "--bus",       "can0@" + endpoint,
          "--state-dir", state_dir};
}

bool AnyLine(NodeProcess& node, const std::string& text) {
  const auto lines = node.LogLines();
  return std::any_of(lines.begin(), lines.end(),
                     [&](const std::string& l) { return l.find(text) != std::string::npos; });
}

/// "085#3081...": an EMCY of `node` with error code 8130h (heartbeat / life guard event).
bool HeartbeatEmcy(const SeenFrame& f, std::uint8_t node) {
  return !f.frame.error() && f.frame.id == 0x80u + node && f.frame.dlc == 8 && f.frame.data[0] == 0x30 &&
         f.frame.data[1] == 0x81;
}
bool HeartbeatOf(const SeenFrame& f, std::uint8_t node) {
  return !f.frame.error() && f.frame.id == 0x700u + node && f.frame.dlc == 1 && f.frame.data[0] != 0;
}

class CanfleetNodeBitRate : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(broker.endpoint().empty());
    ASSERT_TRUE(master.WaitConnected()) << broker.Log();
    a = std::make_unique<NodeProcess>(dir, "a", ValveArgs(kA, broker.endpoint(), dir.File("state-a")));
    StartB();
    ASSERT_TRUE(master.WaitForFrame("705#00")) << a->Output();
    ASSERT_TRUE(master.WaitForFrame("706#00")) << b->Output();
    // Neither node was given a bit rate: each is commissioned for the bus it is on (500 kbit/s,
    // bit timing index 2), not left at its factory 125 kbit/s (§3.1).
    EXPECT_TRUE(AnyLine(*b, "commissioned for the bus at 500 kbit/s")) << b->Output();
    EXPECT_EQ(master.ReadUnsigned(kB, 0x5B50, 0), 2u);
    // Heartbeats every 100 ms; each node consumes the other's with 500 ms (1016h: node << 16 | ms).
    ASSERT_EQ(master.Write(kA, 0x1016, 1, std::uint64_t{kB} << 16 | 500, 4), SdoAbort::kNone);
    ASSERT_EQ(master.Write(kB, 0x1016, 1, std::uint64_t{kA} << 16 | 500, 4), SdoAbort::kNone);
    ASSERT_EQ(master.Write(kA, 0x1017, 0, 100, 2), SdoAbort::kNone);
    ASSERT_EQ(master.Write(kB, 0x1017, 0, 100, 2), SdoAbort::kNone);
    const std::size_t from = master.Frames().size();
    ASSERT_TRUE(master.WaitForFrame([](const SeenFrame& f) { return HeartbeatOf(f, kA); }, from));
    ASSERT_TRUE(master.WaitForFrame([](const SeenFrame& f) { return HeartbeatOf(f, kB); }, from));
  }

  void StartB() {
    b = std::make_unique<NodeProcess>(dir, "b", ValveArgs(kB, broker.endpoint(), dir.File("state-b")));
  }

  /// Waits until B, at the wrong rate, is cut off: A's consumer raises heartbeat loss (EMCY 8130h
  /// from A), B's heartbeats no longer arrive but their destroyed attempts do (error frames on
  /// 706h), B logs error frames and, if it was already monitoring A (`b_was_monitoring`: a consumer
  /// starts with the first heartbeat, CiA 301 §7.2.8.3.2.2), its consumer's heartbeat loss.
  void ExpectBCutOff(std::size_t from, bool b_was_monitoring) {
    EXPECT_TRUE(master.WaitForFrame([](const SeenFrame& f) { return HeartbeatEmcy(f, kA); }, from))
        << a->Output();
    EXPECT_TRUE(
        master.WaitForFrame([](const SeenFrame& f) { return f.frame.error() && f.frame.id == 0x706; }, from))
        << b->Output();
    // No heartbeat of B for a whole second (5 periods), while A's keep coming.
    const std::size_t quiet = master.Frames().size();
    master.RunFor(1s);
    const auto& frames = master.Frames();
    EXPECT_TRUE(std::none_of(frames.begin() + static_cast<std::ptrdiff_t>(quiet), frames.end(),
                             [](const SeenFrame& f) { return HeartbeatOf(f, kB); }));
    EXPECT_TRUE(std::any_of(frames.begin() + static_cast<std::ptrdiff_t>(quiet), frames.end(),
                            [](const SeenFrame& f) { return HeartbeatOf(f, kA); }));
    EXPECT_TRUE(master.RunUntil([&] {
      return AnyLine(*b, "error frames (first: ") &&
             AnyLine(*b, "the controller runs at 250000 bit/s, the bus at 500000");
    })) << b->Output();
    // B's consumer of A (communication error 0, heartbeat, of node 5) was raised.
    if (b_was_monitoring) {
      EXPECT_TRUE(master.RunUntil([&] { return AnyLine(*b, kConsumerOfA + " raised"); })) << b->Output();
    }
  }

  /// Waits until B is back: its heartbeats reach the master again, A's consumer of B clears, and
  /// B's consumer of A clears if it had raised.
  void ExpectBBack(std::size_t from, bool b_was_monitoring) {
    EXPECT_TRUE(master.WaitForFrame([](const SeenFrame& f) { return HeartbeatOf(f, kB); }, from))
        << b->Output();
    EXPECT_TRUE(master.RunUntil([&] { return AnyLine(*a, kConsumerOfB + " cleared"); })) << a->Output();
    if (b_was_monitoring) {
      EXPECT_TRUE(master.RunUntil([&] { return AnyLine(*b, kConsumerOfA + " cleared"); })) << b->Output();
    }
  }

  /// The node process's log of its consumer's heartbeat timeout (kind 0) for node 5.
  inline static const std::string kConsumerOfA = "communication error 0 (detail 5)";
  inline static const std::string kConsumerOfB = "communication error 0 (detail 6)";

  /// CiA 305 §8.3.1.2 switch state selective to B (vendor, product, revision, serial of its 1018h):
  /// B answers 7E4h cs 44h and is in LSS configuration; A stays waiting.
  void SelectB() {
    const std::size_t from = master.Frames().size();
    for (std::uint8_t sub = 1; sub <= 4; ++sub) {
      const auto value = master.ReadUnsigned(kB, 0x1018, sub);
      ASSERT_TRUE(value.has_value());
      const auto v = static_cast<std::uint32_t>(*value);
      SendLss(static_cast<std::uint8_t>(0x40 + sub - 1),
              {static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8),
               static_cast<std::uint8_t>(v >> 16), static_cast<std::uint8_t>(v >> 24)});
    }
    ASSERT_TRUE(master.WaitForFrame("7E4#4400000000000000", from));
  }
  /// Configure bit timing (table 0, `index`), answered; then activate with a 100 ms switch delay.
  void SwitchSelectedTo(std::uint8_t index) {
    const std::size_t from = master.Frames().size();
    SendLss(0x13, {0, index});
    ASSERT_TRUE(master.WaitForFrame("7E4#1300000000000000", from)) << b->Output();
    SendLss(0x15, {100, 0});
  }
  void SendLss(std::uint8_t cs, std::initializer_list<std::uint8_t> data) {
    CanFrame f;
    f.id = 0x7E5;
    f.dlc = 8;
    f.data[0] = cs;
    std::size_t i = 1;
    for (std::uint8_t d : data)
      f.data[i++] = d;
    ASSERT_TRUE(master.port().Send(f));
    master.RunFor(20ms);  // let it leave
  }
  /// The master's own controller (the tool) switches rate: 0 = back to the bus's.
  void MasterAt(std::uint32_t bitrate) {
    ASSERT_TRUE(master.port().SetBitRate(bitrate));
    master.RunFor(100ms);  // the BitRate message reaches the broker before what follows
  }

  TempDir dir;
  BrokerProcess broker{dir, "tcp://127.0.0.1:0"};
  BusMaster master{broker.endpoint()};
  std::unique_ptr<NodeProcess> a, b;
};

// LSS: B alone switched to 250 kbit/s is cut off; a master that meets it at 250 kbit/s switches it
// back by LSS, and everything is normal again.
TEST_F(CanfleetNodeBitRate, LssActivateBitTimingCutsANodeOffAndSwitchingItBackRestoresIt) {
  SelectB();
  const std::size_t switched = master.Frames().size();
  SwitchSelectedTo(3);  // 250 kbit/s
  EXPECT_TRUE(master.RunUntil([&] { return AnyLine(*b, "CAN1: bit rate now 250 kbit/s"); })) << b->Output();
  ExpectBCutOff(switched, true);
  // At the bus's rate the master cannot reach B: its LSS request goes unanswered.
  std::size_t from = master.Frames().size();
  SendLss(0x13, {0, 2});
  EXPECT_FALSE(master.WaitForFrame("7E4#1300000000000000", from, 1s));

  // A tool at B's rate reaches it (B is still in LSS configuration): back to 500 kbit/s. While
  // the tool and B are at 250 kbit/s, A is the one alone at its rate (README "Bit rate": its
  // frames are destroyed too); the tool returns before B's first switch delay ends.
  MasterAt(250'000);
  SwitchSelectedTo(2);
  from = master.Frames().size();
  MasterAt(0);
  ExpectBBack(from, true);
  SendLss(0x04, {0});  // switch state global: waiting
  EXPECT_TRUE(AnyLine(*b, "CAN1: bit rate now 500 kbit/s")) << b->Output();
  EXPECT_TRUE(a->process().Running()) << a->Output();
  EXPECT_TRUE(b->process().Running()) << b->Output();
}

// 5B50h (§3.4.110, Table 32 index 3 = 250 kbit/s), stored with 1010h and taking effect at NMT
// reset node; set back the same way by a master at B's rate. A power cycle keeps the stored rate.
TEST_F(CanfleetNodeBitRate, AStored5B50hTakesEffectAtResetAndSurvivesAPowerCycle) {
  ASSERT_EQ(master.Write(kB, 0x5B50, 0, 3, 1), SdoAbort::kNone);
  ASSERT_EQ(master.Write(kB, 0x1010, 1, 0x65766173, 4), SdoAbort::kNone);  // "save" all
  const std::size_t reset = master.Frames().size();
  ASSERT_TRUE(master.Nmt(BusMaster::kNmtResetNode, kB));
  EXPECT_TRUE(master.RunUntil([&] { return AnyLine(*b, "CAN1: bit rate now 250 kbit/s"); })) << b->Output();
  ExpectBCutOff(reset, false);  // reset: B's consumer waits for a first heartbeat of A

  // Power cycle: B comes back at its stored 250 kbit/s (its boot-up is destroyed, not received).
  b.reset();
  std::size_t from = master.Frames().size();
  StartB();
  EXPECT_TRUE(
      master.WaitForFrame([](const SeenFrame& f) { return f.frame.error() && f.frame.id == 0x706; }, from))
      << b->Output();
  EXPECT_FALSE(master.WaitForFrame("706#00", from, 1s));

  // A master at 250 kbit/s writes the bus's rate back (index 2), stores it and resets B.
  MasterAt(250'000);
  EXPECT_EQ(master.ReadUnsigned(kB, 0x5B50, 0), 3u);
  ASSERT_EQ(master.Write(kB, 0x5B50, 0, 2, 1), SdoAbort::kNone);
  ASSERT_EQ(master.Write(kB, 0x1010, 1, 0x65766173, 4), SdoAbort::kNone);
  ASSERT_TRUE(master.Nmt(BusMaster::kNmtResetNode, kB));
  MasterAt(0);
  from = master.Frames().size();
  ExpectBBack(from, false);
  EXPECT_EQ(master.ReadUnsigned(kB, 0x5B50, 0), 2u);
}

// --factory-bit-rate: a factory-new node C (node-ID 7, nothing configured) keeps the manual's
// factory 125 kbit/s (UMAX020411A §3.1, 5B50h default 4, Table 32) on the 500 kbit/s bus: its
// boot-up and heartbeats are destroyed (error frames on 707h, never a valid one) until a master
// meets it at its rate, which reads its 5B50h there.
TEST_F(CanfleetNodeBitRate, AFactoryNewNodeOnABusAtAnotherRateIsCutOffUntilAMasterMeetsItsRate) {
  std::size_t from = master.Frames().size();
  auto args = ValveArgs(7, broker.endpoint(), dir.File("state-c"));
  args.push_back("--factory-bit-rate");
  NodeProcess c(dir, "c", args);
  EXPECT_TRUE(master.RunUntil([&] {
    return AnyLine(c, "factory bit rate 125 kbit/s kept on a bus at 500 kbit/s");
  })) << c.Output();
  EXPECT_TRUE(
      master.WaitForFrame([](const SeenFrame& f) { return f.frame.error() && f.frame.id == 0x707; }, from))
      << c.Output();
  EXPECT_FALSE(master.WaitForFrame("707#00", from, 1s));
  // A master at 125 kbit/s reaches it: 5B50h reads the factory index 4.
  MasterAt(125'000);
  EXPECT_EQ(master.ReadUnsigned(7, 0x5B50, 0), 4u);
  MasterAt(0);
  EXPECT_TRUE(c.process().Running()) << c.Output();
}

}  // namespace
}  // namespace canfleet::system_test
