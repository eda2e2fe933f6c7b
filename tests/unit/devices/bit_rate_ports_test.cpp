// A node's bit rate reaches its bus port (issue 15 point 5): DeviceNode makes each port follow its
// stack's bit timing (CiA 305 §8.3.2 activate bit timing; the Axiomatic 5B50h, UMAX020411A
// §3.4.110 and UMAX181001 §3.4.79), and canfleet-node commissions a port nobody configured for the
// bus it is plugged into (node/process/bit_rate_commissioning.hpp).
#include <gtest/gtest.h>

#include <tuple>

#include "bus/loopback_bus.hpp"
#include "node/devices/device_node.hpp"
#include "node/devices/registry.hpp"
#include "node/process/bit_rate_commissioning.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::devices {
namespace {

using namespace std::chrono_literals;

/// A port on a loopback bus whose rate can be set, as a broker client port's: records each rate.
class RatePort final : public BusPort {
 public:
  explicit RatePort(LoopbackPort& inner) : inner_(inner) {
    inner_.OnReceive([this](const CanFrame& frame, BusTime time) { Deliver(frame, time); });
  }
  bool Send(const CanFrame& frame) override { return inner_.Send(frame); }
  ControllerState State() const override { return inner_.State(); }
  bool SetBitRate(std::uint32_t bit_per_s) override {
    rates.push_back(bit_per_s);
    return true;
  }
  std::vector<std::uint32_t> rates;

 private:
  LoopbackPort& inner_;
};

using Report = std::tuple<std::size_t, std::uint32_t, bool>;

NodeSettings Settings(std::size_t ports) {
  NodeSettings settings;
  for (std::size_t p = 0; p < ports; ++p)
    settings.ports.push_back({static_cast<std::uint8_t>(5 + p), 4});
  return settings;
}

void Record(DeviceNode& node, std::vector<Report>& reports) {
  node.OnBitRate([&reports](std::size_t port, std::uint32_t kbit, bool applied) {
    reports.emplace_back(port, kbit, applied);
  });
}

std::unique_ptr<Device> Variant(const std::string& name) {
  return MakeDevice({.device = name, .eds = {}});
}

/// LSS switch state global to configuration, configure bit timing (table 0, `index`), activate
/// with a 10 ms switch delay (CiA 305 §8.3.2; UMAX020411A §3.1.1.2).
void LssSwitch(canfleet::test::BusProbe& master, std::uint8_t index) {
  master.Send("7E5#0401000000000000");
  master.Send("7E5#13000" + std::to_string(index) + "0000000000");
  master.Send("7E5#150A000000000000");
}

TEST(DeviceNodeBitRate, LssActivationSwitchesTheBusPortAndIsReported) {
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  RatePort port(bus.Attach("node"));
  canfleet::test::BusProbe master(bus, "master");
  std::vector<Report> reports;
  DeviceNode node(Variant("valve-12in12out"), scheduler, {&port}, Settings(1));
  Record(node, reports);
  node.Start();
  LssSwitch(master, 3);
  EXPECT_TRUE(port.rates.empty());  // CiA 305 fig. 35: after the first switch delay
  scheduler.Advance(10ms);
  EXPECT_EQ(port.rates, (std::vector<std::uint32_t>{250'000}));
  EXPECT_EQ(reports, (std::vector<Report>{{0, 250, true}}));
  EXPECT_EQ(node.od().GetUnsigned(0x5B50, 0), 3u);  // §3.4.110: the object shows the rate
}

// A port whose rate is not the node's to set (SocketCAN; here a plain loopback port) does not
// follow: the report says so, and the node process logs it once.
TEST(DeviceNodeBitRate, APortThatCannotFollowIsReportedAsNotApplied) {
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& port = bus.Attach("node");
  canfleet::test::BusProbe master(bus, "master");
  std::vector<Report> reports;
  DeviceNode node(Variant("power-supply-24v-350w"), scheduler, {&port}, Settings(1));
  Record(node, reports);
  node.Start();
  LssSwitch(master, 2);
  scheduler.Advance(10ms);
  EXPECT_EQ(reports, (std::vector<Report>{{0, 500, false}}));
}

// The data logger (UMAX181001 §3.4.79): 5B50h sub 1 is CAN1's rate, sub 2 CAN2's. LSS on CAN2
// switches port 2 alone, and its sub follows; CAN1 keeps 125 kbit/s.
TEST(DeviceNodeBitRate, TheDataLoggersPortsSwitchOneByOne) {
  SimulatedScheduler scheduler;
  LoopbackBus bus1, bus2;
  RatePort port1(bus1.Attach("node")), port2(bus2.Attach("node"));
  canfleet::test::BusProbe master2(bus2, "master");
  std::vector<Report> reports;
  DeviceNode node(Variant("datalogger-tc-analog"), scheduler, {&port1, &port2}, Settings(2));
  Record(node, reports);
  node.Start();
  LssSwitch(master2, 3);
  scheduler.Advance(10ms);
  EXPECT_TRUE(port1.rates.empty());
  EXPECT_EQ(port2.rates, (std::vector<std::uint32_t>{250'000}));
  EXPECT_EQ(reports, (std::vector<Report>{{1, 250, true}}));
  EXPECT_EQ(node.od(0).GetUnsigned(0x5B50, 1), 4u);
  EXPECT_EQ(node.od(0).GetUnsigned(0x5B50, 2), 3u);
}

// A port that states no rate (no LSS configuration stored) is commissioned for its bus: the stack
// adopts the bus's table-0 index. A stated rate, or a bus rate outside the table, changes nothing.
TEST(BitRateCommissioning, APortNobodyConfiguredTakesItsBussRate) {
  const node::Commissioning at500 = node::CommissionFor(0, 500'000, 4);
  EXPECT_EQ(at500.adopted, std::optional<std::uint8_t>(2));
  EXPECT_NE(at500.message.find("commissioned for the bus at 500 kbit/s"), std::string::npos) << at500.message;
  EXPECT_NE(at500.message.find("factory 125 kbit/s"), std::string::npos) << at500.message;

  const node::Commissioning at125 = node::CommissionFor(0, 125'000, 4);
  EXPECT_EQ(at125.adopted, std::optional<std::uint8_t>(4));
  EXPECT_TRUE(at125.message.empty());  // the factory rate: nothing to say

  EXPECT_FALSE(node::CommissionFor(250'000, 500'000, 4).adopted);  // stated (LSS stored it)
  const node::Commissioning odd = node::CommissionFor(0, 83'333, 4);
  EXPECT_FALSE(odd.adopted);
  EXPECT_NE(odd.message.find("no CiA 305 table-0 index"), std::string::npos);
  EXPECT_FALSE(node::CommissionFor(0, 100'000, 4).adopted);  // index 5 is reserved
}

}  // namespace
}  // namespace canfleet::devices
