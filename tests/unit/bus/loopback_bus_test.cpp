#include "bus/loopback_bus.hpp"

#include <gtest/gtest.h>

#include "tests/support/bus_probe.hpp"

namespace canfleet {
namespace {

TEST(LoopbackBus, DeliversToEveryPortButTheSender) {
  LoopbackBus bus;
  test::BusProbe a(bus, "a"), b(bus, "b"), c(bus, "c");
  a.Send("123#01");
  EXPECT_TRUE(a.Received().empty());
  EXPECT_EQ(b.Take(), std::vector<std::string>{"123#01"});
  EXPECT_EQ(c.Take(), std::vector<std::string>{"123#01"});
}

TEST(LoopbackBus, RepliesSentFromAHandlerArriveAfterTheRequestInBusOrder) {
  LoopbackBus bus;
  auto& responder = bus.Attach("responder");
  int depth = 0, max_depth = 0;
  responder.OnReceive([&](const CanFrame& f, BusTime) {
    ++depth;
    max_depth = std::max(max_depth, depth);
    if (f.id == 0x601) responder.Send(CanFrame::Data(0x581, {0x60}));
    --depth;
  });
  test::BusProbe master(bus, "master");
  master.Send("601#40");
  master.Send("601#40");
  EXPECT_EQ(max_depth, 1);  // never re-entered
  EXPECT_EQ(master.Take(), (std::vector<std::string>{"581#60", "581#60"}));
  ASSERT_EQ(bus.History().size(), 4u);
  EXPECT_EQ(ToCandump(bus.History()[1]), "581#60");
}

TEST(LoopbackBus, BusOffPortCannotSendAndStateChangesAreReported) {
  LoopbackBus bus;
  auto& port = bus.Attach("node");
  test::BusProbe probe(bus);
  std::vector<ControllerState> seen;
  port.OnStateChange([&](const ControllerEvent& e) { seen.push_back(e.state); });
  port.SetControllerState({ControllerState::kBusOff, 256, 0});
  EXPECT_FALSE(port.Send(CanFrame::Data(0x181, {1})));
  EXPECT_EQ(probe.Count(), 0u);
  port.SetControllerState({ControllerState::kErrorActive, 0, 0});
  EXPECT_TRUE(port.Send(CanFrame::Data(0x181, {1})));
  EXPECT_EQ(seen, (std::vector<ControllerState>{ControllerState::kBusOff, ControllerState::kErrorActive}));
}

TEST(LoopbackBus, InvalidFramesAreRefused) {
  LoopbackBus bus;
  auto& port = bus.Attach("node");
  test::BusProbe probe(bus);
  CanFrame bad;
  bad.dlc = 12;
  EXPECT_FALSE(port.Send(bad));
  EXPECT_EQ(probe.Count(), 0u);
}

}  // namespace
}  // namespace canfleet
