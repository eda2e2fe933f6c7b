// Nothing a peer sends may crash, hang or wedge the SDO server or client (CONTRIBUTING.md): after
// thousands of random and truncated frames, valid transfers still work.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "node/canopen/sdo/sdo_client.hpp"
#include "tests/unit/sdo/sdo_test_bench.hpp"

namespace canfleet::canopen {
namespace {

using namespace std::chrono_literals;
using test::ServerBench;

/// Random frames biased towards what the server understands, so the state machine gets deep.
class FrameSource {
 public:
  explicit FrameSource(std::uint32_t seed) : rng_(seed) {}

  CanFrame Next(std::uint32_t id) {
    static constexpr std::uint8_t kCommands[] = {0x20, 0x21, 0x22, 0x23, 0x27, 0x2B, 0x2F, 0x40, 0x60, 0x70,
                                                 0x00, 0x10, 0x01, 0x11, 0x0B, 0x80, 0xA0, 0xA4, 0xA1, 0xA2,
                                                 0xA3, 0xC0, 0xC2, 0xC4, 0xC6, 0xC1, 0xD1, 0x81, 0x82, 0x7F};
    static constexpr std::uint16_t kIndexes[] = {0x2004, 0x1008, 0x1000, 0x1017,
                                                 0x2001, 0x2003, 0x2006, 0x1200};
    CanFrame f;
    f.id = id;
    f.dlc = Pick(10) < 8 ? 8 : static_cast<std::uint8_t>(Pick(9));  // 20 % truncated (or 8 anyway)
    if (Pick(50) == 0) f.flags = CanFrame::kRemote;
    for (auto& b : f.data)
      b = static_cast<std::uint8_t>(rng_());
    if (Pick(4) != 0) f.data[0] = kCommands[Pick(std::size(kCommands))];
    if (Pick(3) != 0) {
      const auto index = kIndexes[Pick(std::size(kIndexes))];
      f.data[1] = static_cast<std::uint8_t>(index);
      f.data[2] = static_cast<std::uint8_t>(index >> 8);
      f.data[3] = static_cast<std::uint8_t>(Pick(3));
    }
    if (Pick(2) == 0) {  // small sizes, blksize and pst
      f.data[4] = static_cast<std::uint8_t>(Pick(40));
      f.data[5] = static_cast<std::uint8_t>(Pick(3) == 0 ? Pick(20) : 0);
      f.data[6] = f.data[7] = 0;
    }
    return f;
  }
  std::size_t Pick(std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_); }

 private:
  std::mt19937 rng_;
};

TEST(SdoRobustness, RandomFramesNeverWedgeTheServer) {
  int direct = 0, after_timeout = 0;
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    ServerBench b(SdoServerOptions{.max_transfer_bytes = 4096});
    FrameSource source(seed);
    for (int i = 0; i < 2500; ++i) {
      b.probe.Send(source.Next(0x605));
      if (source.Pick(40) == 0) b.scheduler.Advance(std::chrono::milliseconds(source.Pick(1500)));
      if (source.Pick(500) == 0) b.server.SetEnabled(false);
      if (source.Pick(50) == 0) b.server.SetEnabled(true);
    }
    for (const auto& f : b.bus.History()) {
      if (f.id != 0x585) continue;
      ASSERT_EQ(f.dlc, 8) << ToCandump(f);  // every response is a full SDO frame
    }
    b.server.SetEnabled(true);
    b.probe.Clear();
    // A new request is served at once, except inside a block download sub-block where it reads as
    // a segment (§7.2.4.3.10); the SDO timeout always brings the server back.
    b.probe.Send("605#4000100000000000");
    if (b.probe.Take() == std::vector<std::string>{"585#4300100094010F00"}) {
      ++direct;
    } else {
      b.scheduler.Advance(1s);
      b.probe.Clear();
      b.probe.Send("605#4000100000000000");
      ASSERT_EQ(b.probe.Take(), std::vector<std::string>{"585#4300100094010F00"}) << "seed " << seed;
      ++after_timeout;
    }
    // And a complete block transfer in both directions.
    LoopbackPort& client_port = b.bus.Attach("client");
    SdoClient client(client_port, b.scheduler);
    client_port.OnReceive([&](const CanFrame& f, BusTime) { client.OnFrame(f); });
    const Bytes value(1000, static_cast<std::uint8_t>(seed));
    SdoAbort written = SdoAbort::kGeneralError, read = SdoAbort::kGeneralError;
    Bytes data;
    client.Download(5, 0x2004, 0, value, SdoMode::kBlock, [&](SdoAbort rc) { written = rc; });
    client.Upload(5, 0x2004, 0, SdoMode::kBlock, [&](SdoAbort rc, Bytes d) {
      read = rc;
      data = std::move(d);
    });
    EXPECT_EQ(written, SdoAbort::kNone) << "seed " << seed;
    EXPECT_EQ(read, SdoAbort::kNone) << "seed " << seed;
    EXPECT_EQ(data, value);
  }
  EXPECT_GT(direct, after_timeout);  // the slow path is the exception
}

TEST(SdoRobustness, RandomResponsesNeverWedgeTheClient) {
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    SimulatedScheduler scheduler;
    LoopbackBus bus;
    LoopbackPort& port = bus.Attach("client");
    canfleet::test::BusProbe server(bus, "server");
    SdoClient client(port, scheduler, SdoClientOptions{.max_upload_bytes = 4096});
    port.OnReceive([&](const CanFrame& f, BusTime) { client.OnFrame(f); });
    FrameSource source(seed);
    int started = 0, completed = 0;
    for (int i = 0; i < 2500; ++i) {
      if (!client.Busy()) {
        const auto mode = static_cast<SdoMode>(source.Pick(3));
        const bool ok =
            source.Pick(2) == 0
                ? client.Upload(5, 0x2004, 0, mode, [&](SdoAbort, Bytes) { ++completed; })
                : client.Download(5, 0x2004, 0, Bytes(source.Pick(30)), mode, [&](SdoAbort) { ++completed; });
        ASSERT_TRUE(ok);
        ++started;
      }
      server.Send(source.Next(0x585));
      if (source.Pick(40) == 0) scheduler.Advance(std::chrono::milliseconds(source.Pick(1500)));
    }
    scheduler.Advance(2s);  // the timeout ends whatever is left
    EXPECT_FALSE(client.Busy());
    EXPECT_EQ(started, completed) << "seed " << seed;  // every request completed exactly once
    for (const auto& f : bus.History()) {
      if (f.id == 0x605) {
        ASSERT_EQ(f.dlc, 8) << ToCandump(f);
      }
    }
  }
}

}  // namespace
}  // namespace canfleet::canopen
