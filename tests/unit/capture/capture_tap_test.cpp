// A capture is a listen-only port of a broker bus: it records every frame at its bus time on the
// wall clock, error frames included, without changing the bus (ISO 11898-1 bus monitoring mode).
#include "orchestrator/capture/capture_tap.hpp"

#include <gtest/gtest.h>

#include "bus/capture/candump_log.hpp"
#include "orchestrator/broker/broker.hpp"
#include "tests/support/bus_probe.hpp"
#include "tests/unit/broker/broker_test_support.hpp"
#include "tests/unit/capture/capture_test_support.hpp"

namespace canfleet::capture {
namespace {

using canfleet::test::Frame;
using namespace std::chrono_literals;

/// Keeps what a tap writes, as candump log lines.
class MemoryWriter final : public CaptureWriter {
 public:
  void Write(const CanFrame& frame, WallTime time) override {
    AppendCandumpLogLine(text, frame, time, "can0");
  }
  void Flush() override {}
  void Close() override {}
  bool ok() const override { return true; }
  const std::string& error() const override { return error_; }
  std::string text;

 private:
  std::string error_;
};

class CaptureTapTest : public ::testing::Test {
 protected:
  SimulatedScheduler s;
  broker::Broker broker{s};
  bool bus_added = (broker.AddBus({.name = "can0", .bitrate = 500'000}), true);
  MemoryWriter writer;
  CaptureTap tap{writer, test::At(1700000000)};
  broker::PortId tap_port = broker.Attach("can0", "capture", tap, CaptureTap::kAttachOptions);
};

// Frame durations as in tests/unit/broker/paced_test.cpp: at 500 kbit/s 000# ends at 106 µs,
// then 123#1122334455667788 at 330 µs.
TEST_F(CaptureTapTest, WritesEveryFrameAtItsBusTimeOnTheWallClock) {
  broker::test::RecordingSink a, b;
  const auto pa = broker.Attach("can0", "a", a);
  const auto pb = broker.Attach("can0", "b", b);
  broker.Submit(pa, Frame("123#1122334455667788"));
  broker.Submit(pb, Frame("000#"));
  s.Advance(10ms);
  EXPECT_EQ(writer.text,
            "(1700000000.000106) can0 000#\n"
            "(1700000000.000330) can0 123#1122334455667788\n");
  EXPECT_EQ(tap.frames(), 2u);
}

// A node alone on the bus (with only a capture listening) gets no ACK: it goes error-passive
// (ISO 11898-1:2015 §12.1.4.2, rule 3 exception 1), and the capture records the error frames.
TEST_F(CaptureTapTest, ListensWithoutAcknowledgingAndRecordsErrorFrames) {
  broker::test::RecordingSink lone{&s};
  const auto port = broker.Attach("can0", "lone", lone);
  broker.Submit(port, Frame("181#01"));
  s.Advance(20ms);
  EXPECT_EQ(lone.States(), (std::vector<ControllerState>{ControllerState::kErrorPassive}));
  EXPECT_TRUE(lone.confirmed.empty());
  ASSERT_GE(writer.text.size(), 1u);
  EXPECT_EQ(writer.text.substr(0, writer.text.find('\n') + 1).substr(20), "can0 20000088#0000000000000000\n");
  EXPECT_EQ(writer.text.find("181#"), std::string::npos) << "a frame nobody acknowledged never completed";
}

TEST(WallClockOrigin, IsNowMinusSchedulerTime) {
  SimulatedScheduler s;
  s.Advance(10s);
  const auto before = std::chrono::system_clock::now();
  const WallTime origin = WallClockOrigin(s);
  const auto after = std::chrono::system_clock::now();
  EXPECT_GE(origin + 10s, std::chrono::time_point_cast<std::chrono::nanoseconds>(before));
  EXPECT_LE(origin + 10s, std::chrono::time_point_cast<std::chrono::nanoseconds>(after));
}

}  // namespace
}  // namespace canfleet::capture
