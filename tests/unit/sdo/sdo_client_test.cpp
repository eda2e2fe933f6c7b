// SDO client against the SDO server (round trips in every mode, CiA 301 v4.2 §7.2.4.3.2–15), the
// client's own frames and error handling against a scripted server, and recovery from lost frames.
#include "node/canopen/sdo/sdo_client.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "tests/unit/sdo/sdo_test_bench.hpp"

namespace canfleet::canopen {
namespace {

using namespace std::chrono_literals;
using canfleet::test::BusProbe;
using Frames = std::vector<std::string>;

Bytes RandomBytes(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  Bytes out(n);
  for (auto& b : out)
    b = static_cast<std::uint8_t>(rng());
  return out;
}

/// What a callback reported.
struct Outcome {
  bool called = false;
  SdoAbort abort = SdoAbort::kNone;
  Bytes data;
};

SdoUploadCallback Into(Outcome& o) {
  return [&o](SdoAbort abort, Bytes data) {
    EXPECT_FALSE(o.called) << "callback called twice";
    o = {true, abort, std::move(data)};
  };
}
SdoDownloadCallback IntoDownload(Outcome& o) {
  return [&o](SdoAbort abort) {
    EXPECT_FALSE(o.called) << "callback called twice";
    o = {true, abort, {}};
  };
}

std::string Hex(SdoAbort code) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%08X", static_cast<unsigned>(code));
  return buf;
}

/// Server (node 5) and client on one loopback bus; the bus history shows every frame.
struct ClientBench {
  explicit ClientBench(SdoClientOptions client_options = {}, SdoServerOptions server_options = {})
      : server(od, server_port, scheduler, server_options), client(client_port, scheduler, client_options) {
    test::AddSdoTestObjects(od, veto);
    server_port.OnReceive([this](const CanFrame& f, BusTime) { server.OnFrame(f); });
    client_port.OnReceive([this](const CanFrame& f, BusTime) { client.OnFrame(f); });
    server.SetNodeId(5);
  }
  Frames History() const {
    Frames out;
    for (const auto& f : bus.History())
      out.push_back(ToCandump(f));
    return out;
  }

  SdoAbort veto = SdoAbort::kNone;
  ObjectDictionary od;
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& server_port = bus.Attach("server");
  LoopbackPort& client_port = bus.Attach("client");
  SdoServer server;
  SdoClient client;
};

// ---- round trips -------------------------------------------------------------------------------

class SdoRoundTrip : public ::testing::TestWithParam<std::tuple<std::size_t, SdoMode>> {};

TEST_P(SdoRoundTrip, DownloadThenUploadGivesTheSameBytes) {
  const auto [size, mode] = GetParam();
  ClientBench b;
  const Bytes value = RandomBytes(size, static_cast<std::uint32_t>(size));

  Outcome written;
  ASSERT_TRUE(b.client.Download(5, 0x2004, 0, value, mode, IntoDownload(written)));
  ASSERT_TRUE(written.called);  // a loopback bus completes the exchange synchronously
  EXPECT_EQ(written.abort, SdoAbort::kNone) << Hex(written.abort);
  EXPECT_EQ(b.od.Find(0x2004, 0)->value, value);

  Outcome read;
  ASSERT_TRUE(b.client.Upload(5, 0x2004, 0, mode, Into(read)));
  ASSERT_TRUE(read.called);
  EXPECT_EQ(read.abort, SdoAbort::kNone) << Hex(read.abort);
  EXPECT_EQ(read.data, value);
  EXPECT_FALSE(b.client.Busy());
  EXPECT_FALSE(b.server.Busy());

  // The mode really was used: byte 0 of the first request says so.
  const std::uint8_t first = b.bus.History().front().data[0];
  if (mode == SdoMode::kBlock) {
    EXPECT_EQ(first, 0xC6);
  } else if (mode == SdoMode::kAuto && size <= 4) {
    EXPECT_EQ(first, 0x23 | (4 - size) << 2);
  } else {
    EXPECT_EQ(first, 0x21);
  }
}

std::string RoundTripName(const ::testing::TestParamInfo<SdoRoundTrip::ParamType>& param_info) {
  static const char* const kModes[] = {"Auto", "Segmented", "Block"};
  return kModes[static_cast<int>(std::get<1>(param_info.param))] +
         std::to_string(std::get<0>(param_info.param));
}

INSTANTIATE_TEST_SUITE_P(SizesAndModes, SdoRoundTrip,
                         ::testing::Combine(::testing::Values(1, 4, 5, 7, 8, 889, 4096, 100000),
                                            ::testing::Values(SdoMode::kAuto, SdoMode::kSegmented,
                                                              SdoMode::kBlock)),
                         RoundTripName);

TEST(SdoClient, RoundTripOfAnEmptyDomainInEveryMode) {
  for (SdoMode mode : {SdoMode::kAuto, SdoMode::kSegmented, SdoMode::kBlock}) {
    ClientBench b;
    b.od.Write(0x2004, 0, Bytes{1, 2}, Origin::kDevice);
    Outcome written, read;
    ASSERT_TRUE(b.client.Download(5, 0x2004, 0, {}, mode, IntoDownload(written)));
    EXPECT_EQ(written.abort, SdoAbort::kNone);
    EXPECT_TRUE(b.od.Find(0x2004, 0)->value.empty());
    ASSERT_TRUE(b.client.Upload(5, 0x2004, 0, mode, Into(read)));
    EXPECT_EQ(read.abort, SdoAbort::kNone);
    EXPECT_TRUE(read.data.empty());
  }
}

TEST(SdoClient, TypedObjectsRoundTrip) {
  ClientBench b;
  Outcome written, read;
  b.client.Download(5, 0x1017, 0, EncodeLe<std::uint16_t>(1500), SdoMode::kAuto, IntoDownload(written));
  EXPECT_EQ(written.abort, SdoAbort::kNone);
  b.client.Upload(5, 0x1017, 0, SdoMode::kBlock, Into(read));
  EXPECT_EQ(DecodeUnsignedLe(read.data), 1500u);
}

// ---- the client's frames -----------------------------------------------------------------------

TEST(SdoClient, ExpeditedFrames) {
  ClientBench b;
  Outcome read, written;
  b.client.Upload(5, 0x1000, 0, SdoMode::kAuto, Into(read));
  b.client.Download(5, 0x1017, 0, EncodeLe<std::uint16_t>(1000), SdoMode::kAuto, IntoDownload(written));
  EXPECT_EQ(b.History(), (Frames{"605#4000100000000000", "585#4300100094010F00", "605#2B171000E8030000",
                                 "585#6017100000000000"}));
  EXPECT_EQ(read.data, EncodeLe<std::uint32_t>(0x000F0194));
}

TEST(SdoClient, SegmentedFrames) {
  ClientBench b;
  Outcome written, read;
  b.client.Download(5, 0x2004, 0, ToBytes("0123456789"), SdoMode::kAuto, IntoDownload(written));
  b.client.Upload(5, 0x1008, 0, SdoMode::kAuto, Into(read));
  EXPECT_EQ(b.History(), (Frames{"605#210420000A000000", "585#6004200000000000", "605#0030313233343536",
                                 "585#2000000000000000", "605#1937383900000000", "585#3000000000000000",
                                 "605#4008100000000000", "585#410810000F000000", "605#6000000000000000",
                                 "585#0063616E666C6565", "605#7000000000000000", "585#1074207365727665",
                                 "605#6000000000000000", "585#0D72000000000000"}));
  EXPECT_EQ(read.data, ToBytes("canfleet server"));
}

TEST(SdoClient, BlockFrames) {
  ClientBench b;
  Outcome written, read;
  b.client.Download(5, 0x2004, 0, ToBytes("0123456789"), SdoMode::kBlock, IntoDownload(written));
  b.client.Upload(5, 0x1008, 0, SdoMode::kBlock, Into(read));
  EXPECT_EQ(b.History(), (Frames{"605#C60420000A000000", "585#A40420007F000000", "605#0130313233343536",
                                 "605#8237383900000000", "585#A2027F0000000000", "605#D1589C0000000000",
                                 "585#A100000000000000", "605#A40810007F000000", "585#C60810000F000000",
                                 "605#A300000000000000", "585#0163616E666C6565", "585#0274207365727665",
                                 "585#8372000000000000", "605#A2037F0000000000", "585#D949C60000000000",
                                 "605#A100000000000000"}));
  EXPECT_EQ(read.data, ToBytes("canfleet server"));
}

TEST(SdoClient, BlockUploadBelowPstSwitchesToANormalUpload) {
  ClientBench b(SdoClientOptions{.pst = 16});
  Outcome small, large;
  b.client.Upload(5, 0x1008, 0, SdoMode::kBlock, Into(small));
  EXPECT_EQ(small.data, ToBytes("canfleet server"));
  b.client.Upload(5, 0x1000, 0, SdoMode::kBlock, Into(large));
  EXPECT_EQ(large.data, EncodeLe<std::uint32_t>(0x000F0194));
  const Frames history = b.History();
  EXPECT_EQ(history[0], "605#A40810007F100000");
  EXPECT_EQ(history[1], "585#410810000F000000");
  EXPECT_EQ(history[2], "605#6000000000000000");
}

TEST(SdoClient, ServerAbortIsReported) {
  ClientBench b;
  Outcome read, written;
  b.client.Upload(5, 0x3000, 0, SdoMode::kAuto, Into(read));
  EXPECT_EQ(read.abort, SdoAbort::kNoObject);
  EXPECT_TRUE(read.data.empty());
  b.veto = SdoAbort::kDeviceState;
  b.client.Download(5, 0x2003, 0, EncodeLe<std::uint16_t>(1), SdoMode::kBlock, IntoDownload(written));
  EXPECT_EQ(written.abort, SdoAbort::kDeviceState);
  EXPECT_FALSE(b.client.Busy());
}

TEST(SdoClient, CallbackMayStartTheNextTransfer) {
  ClientBench b;
  Outcome second;
  bool first_done = false;
  b.client.Upload(5, 0x1000, 0, SdoMode::kAuto, [&](SdoAbort abort, Bytes) {
    first_done = abort == SdoAbort::kNone;
    EXPECT_FALSE(b.client.Busy());
    EXPECT_TRUE(b.client.Upload(5, 0x1008, 0, SdoMode::kBlock, Into(second)));
  });
  EXPECT_TRUE(first_done);
  EXPECT_EQ(second.data, ToBytes("canfleet server"));
}

// ---- against a scripted server -----------------------------------------------------------------

struct ScriptBench {
  explicit ScriptBench(SdoClientOptions options = {}) : client(port, scheduler, options) {
    port.OnReceive([this](const CanFrame& f, BusTime) { client.OnFrame(f); });
  }
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& port = bus.Attach("client");
  BusProbe server{bus, "server"};
  SdoClient client;
};

TEST(SdoClientScript, RefusesWhenBusyOrForAnInvalidNodeId) {
  ScriptBench s;
  Outcome o;
  EXPECT_FALSE(s.client.Upload(0, 0x1000, 0, SdoMode::kAuto, Into(o)));
  EXPECT_FALSE(s.client.Upload(128, 0x1000, 0, SdoMode::kAuto, Into(o)));
  EXPECT_TRUE(s.client.Upload(7, 0x1000, 0, SdoMode::kAuto, Into(o)));
  EXPECT_FALSE(s.client.Download(7, 0x1000, 0, Bytes{1}, SdoMode::kAuto, IntoDownload(o)));
  EXPECT_EQ(s.server.Take(), (Frames{"607#4000100000000000"}));
  EXPECT_FALSE(o.called);
}

TEST(SdoClientScript, TimeoutSendsAbortAndReportsIt) {
  ScriptBench s;
  Outcome o;
  s.client.Upload(7, 0x1018, 1, SdoMode::kAuto, Into(o));
  s.server.Clear();
  s.scheduler.Advance(999ms);
  EXPECT_FALSE(o.called);
  s.scheduler.Advance(1ms);
  EXPECT_EQ(s.server.Next(), "607#8018100100000405");
  EXPECT_TRUE(o.called);
  EXPECT_EQ(o.abort, SdoAbort::kTimeout);
  EXPECT_FALSE(s.client.Busy());
}

TEST(SdoClientScript, TheServersAbortIsNotAnswered) {
  ScriptBench s;
  Outcome o;
  s.client.Download(7, 0x2000, 0, Bytes(20, 0xAA), SdoMode::kSegmented, IntoDownload(o));
  s.server.Clear();
  s.server.Send("587#8000200022000008");
  EXPECT_EQ(o.abort, SdoAbort::kDeviceState);
  EXPECT_EQ(s.server.Count(), 0u);
}

TEST(SdoClientScript, ToggleErrorAborts) {
  ScriptBench s;
  Outcome o;
  s.client.Upload(7, 0x1008, 0, SdoMode::kAuto, Into(o));
  s.server.Send("587#4108100014000000");
  EXPECT_EQ(s.server.Take(), (Frames{"607#4008100000000000", "607#6000000000000000"}));
  s.server.Send("587#1041424344454647");  // t = 1 in the first segment
  EXPECT_EQ(s.server.Next(), "607#8008100000000305");
  EXPECT_EQ(o.abort, SdoAbort::kToggleBit);
}

TEST(SdoClientScript, ResponseForAnotherObjectAborts) {
  ScriptBench s;
  Outcome o;
  s.client.Upload(7, 0x1017, 0, SdoMode::kAuto, Into(o));
  s.server.Clear();
  s.server.Send("587#4B181000E8030000");
  EXPECT_EQ(s.server.Next(), "607#8017100043000406");  // 06040043, as CANopenNode's client
  EXPECT_EQ(o.abort, SdoAbort::kParameterIncompatible);
}

TEST(SdoClientScript, UnexpectedSpecifierAborts) {
  ScriptBench s;
  Outcome o;
  s.client.Upload(7, 0x1017, 0, SdoMode::kAuto, Into(o));
  s.server.Clear();
  s.server.Send("587#6017100000000000");  // a download response to an upload
  EXPECT_EQ(s.server.Next(), "607#8017100001000405");
  EXPECT_EQ(o.abort, SdoAbort::kInvalidCommand);
}

TEST(SdoClientScript, ShortFramesAndOtherNodesAreIgnored) {
  ScriptBench s;
  Outcome o;
  s.client.Upload(7, 0x1017, 0, SdoMode::kAuto, Into(o));
  s.server.Clear();
  EXPECT_TRUE(s.client.OnFrame(canfleet::test::Frame("587#4B171000")));
  EXPECT_FALSE(s.client.OnFrame(canfleet::test::Frame("588#4B171000E8030000")));
  EXPECT_FALSE(o.called);
  s.server.Send("587#4B171000E8030000");
  EXPECT_EQ(o.data, (Bytes{0xE8, 0x03}));
}

TEST(SdoClientScript, IndicatedSizeAboveTheLimitIsOutOfMemory) {
  ScriptBench s(SdoClientOptions{.max_upload_bytes = 100});
  Outcome o;
  s.client.Upload(7, 0x2004, 0, SdoMode::kAuto, Into(o));
  s.server.Clear();
  s.server.Send("587#4104200065000000");
  EXPECT_EQ(s.server.Next(), "607#8004200005000405");
  EXPECT_EQ(o.abort, SdoAbort::kOutOfMemory);
}

TEST(SdoClientScript, BlockUploadWithWrongCrcAborts) {
  ScriptBench s;
  Outcome o;
  s.client.Upload(7, 0x2004, 0, SdoMode::kBlock, Into(o));
  s.server.Send("587#C604200003000000");
  s.server.Send("587#8141424300000000");
  EXPECT_EQ(s.server.Take(),
            (Frames{"607#A40420007F000000", "607#A300000000000000", "607#A2017F0000000000"}));
  s.server.Send("587#D112340000000000");
  EXPECT_EQ(s.server.Next(), "607#8004200004000405");
  EXPECT_EQ(o.abort, SdoAbort::kCrcError);
}

TEST(SdoClientScript, AbortSendsTheCode) {
  ScriptBench s;
  Outcome o;
  s.client.Download(7, 0x2004, 0, Bytes(100, 1), SdoMode::kBlock, IntoDownload(o));
  s.server.Clear();
  s.client.Abort(SdoAbort::kLocalControl);
  EXPECT_EQ(s.server.Next(), "607#8004200021000008");
  EXPECT_EQ(o.abort, SdoAbort::kLocalControl);
  s.client.Abort();  // nothing in progress: nothing happens
  EXPECT_EQ(s.server.Count(), 0u);
}

// ---- lost frames (client and server on two buses joined by a lossy relay) ----------------------

struct LossyBench {
  LossyBench() : server(od, server_port, scheduler), client(client_port, scheduler) {
    test::AddSdoTestObjects(od, veto);
    server_port.OnReceive([this](const CanFrame& f, BusTime) { server.OnFrame(f); });
    client_port.OnReceive([this](const CanFrame& f, BusTime) { client.OnFrame(f); });
    relay_c.OnReceive([this](const CanFrame& f, BusTime) {
      if (!drop || !drop(f)) relay_s.Send(f);
    });
    relay_s.OnReceive([this](const CanFrame& f, BusTime) {
      if (!drop || !drop(f)) relay_c.Send(f);
    });
    server.SetNodeId(5);
  }
  /// Runs simulated time until the callback came (at most `limit`).
  void RunUntil(const Outcome& o, Duration limit = 10s) {
    for (Duration t{}; !o.called && t < limit; t += 10ms)
      scheduler.Advance(10ms);
  }

  SdoAbort veto = SdoAbort::kNone;
  ObjectDictionary od;
  SimulatedScheduler scheduler;
  LoopbackBus client_bus, server_bus;
  LoopbackPort& client_port = client_bus.Attach("client");
  LoopbackPort& relay_c = client_bus.Attach("relay");
  LoopbackPort& relay_s = server_bus.Attach("relay");
  LoopbackPort& server_port = server_bus.Attach("server");
  SdoServer server;
  SdoClient client;
  std::function<bool(const CanFrame&)> drop;
};

/// Drops the n-th frame (1-based) that matches `match`, once.
std::function<bool(const CanFrame&)> DropOnce(std::function<bool(const CanFrame&)> match, int n) {
  auto count = std::make_shared<int>(0);
  return [match, n, count](const CanFrame& f) { return match(f) && ++*count == n; };
}

TEST(SdoLossy, BlockDownloadRecoversLostMiddleAndLastSegments) {
  LossyBench b;
  const Bytes value = RandomBytes(2000, 1);  // 286 segments: three sub-blocks of 127
  int dropped = 0;
  b.drop = [&](const CanFrame& f) {
    if (f.id != 0x605) return false;
    // Segment 10 of the first sub-block and the last segment (127) of the second.
    static const std::uint8_t victims[] = {10, 127};
    if (dropped < 2 && f.data[0] == victims[dropped]) {
      ++dropped;
      return true;
    }
    return false;
  };
  Outcome o;
  b.client.Download(5, 0x2004, 0, value, SdoMode::kBlock, IntoDownload(o));
  b.RunUntil(o);
  ASSERT_TRUE(o.called);
  EXPECT_EQ(o.abort, SdoAbort::kNone) << Hex(o.abort);
  EXPECT_EQ(dropped, 2);
  EXPECT_EQ(b.od.Find(0x2004, 0)->value, value);
}

TEST(SdoLossy, BlockUploadRecoversLostMiddleAndLastSegments) {
  LossyBench b;
  const Bytes value = RandomBytes(2000, 2);
  b.od.Write(0x2004, 0, value, Origin::kDevice);
  int dropped = 0;
  b.drop = [&](const CanFrame& f) {
    if (f.id != 0x585) return false;
    static const std::uint8_t victims[] = {3, 127};
    if (dropped < 2 && (f.data[0] & 0x7F) == victims[dropped] && (f.data[0] & 0xE0) != 0xC0) {
      ++dropped;
      return true;
    }
    return false;
  };
  Outcome o;
  b.client.Upload(5, 0x2004, 0, SdoMode::kBlock, Into(o));
  b.RunUntil(o);
  ASSERT_TRUE(o.called);
  EXPECT_EQ(o.abort, SdoAbort::kNone) << Hex(o.abort);
  EXPECT_EQ(dropped, 2);
  EXPECT_EQ(o.data, value);
}

TEST(SdoLossy, LostSegmentedResponseTimesOutBothSidesThenTheNextTransferWorks) {
  LossyBench b;
  b.drop = DropOnce([](const CanFrame& f) { return f.id == 0x585 && (f.data[0] & 0xE0) == 0x20; }, 2);
  Outcome o;
  b.client.Download(5, 0x2004, 0, Bytes(30, 7), SdoMode::kSegmented, IntoDownload(o));
  b.RunUntil(o);
  EXPECT_EQ(o.abort, SdoAbort::kTimeout);
  b.scheduler.Advance(2s);
  EXPECT_FALSE(b.server.Busy());
  Outcome again;
  b.client.Download(5, 0x2004, 0, Bytes(30, 7), SdoMode::kSegmented, IntoDownload(again));
  EXPECT_EQ(again.abort, SdoAbort::kNone);
  EXPECT_EQ(b.od.Find(0x2004, 0)->value, Bytes(30, 7));
}

}  // namespace
}  // namespace canfleet::canopen
