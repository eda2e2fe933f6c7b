// CiA 305 v3.0.0 fig. 46, LSS Fastscan, end to end: a minimal master finds two non-configured
// slaves that differ only in their serial number, one after the other, bit by bit, and gives each
// a node-ID. The master is written from the protocol, not from the slave's code.
#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <vector>

#include "node/canopen/lss/lss_slave.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::canopen {
namespace {

using namespace std::chrono_literals;
using test::BusProbe;

/// The LSS master's side of Fastscan over a BusProbe. A real master waits a timeout for 4Fh
/// answers; on the loopback bus every answer arrives inside Send(), and the scheduler is advanced
/// by that timeout anyway so the slaves see master-like timing.
class FastscanMaster {
 public:
  FastscanMaster(BusProbe& probe, SimulatedScheduler& scheduler) : probe_(probe), scheduler_(scheduler) {}

  /// Scans all four address parts; returns the address of the slave left in configuration mode,
  /// or nullopt when no non-configured slave answered.
  std::optional<LssAddress> Scan() {
    if (!Request(0, kFastscanReset, 0, 0)) return std::nullopt;
    std::uint32_t parts[4] = {};
    for (std::uint8_t sub = 0; sub < 4; ++sub) {
      std::uint32_t id = 0;
      // Offer each bit as 0, from bit 31 down: silence means every remaining slave has a 1.
      for (int bit = 31; bit >= 0; --bit) {
        if (!Request(id, static_cast<std::uint8_t>(bit), sub, sub)) id |= 1u << bit;
      }
      // Confirm the complete part and move the slave's LSSPos on; after the serial number
      // LSSNext wraps to 0 < LSSSub and the slave enters configuration.
      const auto next = static_cast<std::uint8_t>((sub + 1) & 3);
      if (!Request(id, 0, sub, next)) return std::nullopt;
      parts[sub] = id;
    }
    return LssAddress{parts[0], parts[1], parts[2], parts[3]};
  }

  std::size_t requests() const { return requests_; }

 private:
  bool Request(std::uint32_t id, std::uint8_t bit_checked, std::uint8_t lss_sub, std::uint8_t lss_next) {
    ++requests_;
    probe_.Clear();
    probe_.Send(LssFrame(kLssMasterToSlaveId, LssCs::kFastscan,
                         {static_cast<std::uint8_t>(id), static_cast<std::uint8_t>(id >> 8),
                          static_cast<std::uint8_t>(id >> 16), static_cast<std::uint8_t>(id >> 24),
                          bit_checked, lss_sub, lss_next}));
    scheduler_.Advance(10ms);
    bool answered = false;
    for (const auto& reply : probe_.Take()) {
      EXPECT_EQ(reply, "7E4#4F00000000000000");
      answered = true;
    }
    return answered;
  }

  BusProbe& probe_;
  SimulatedScheduler& scheduler_;
  std::size_t requests_ = 0;
};

/// One slave node as the stack would run it: LSS plus the "reset communication" callback.
struct Node {
  Node(LoopbackBus& bus, SimulatedScheduler& scheduler, const char* name, LssAddress address)
      : port(bus.Attach(name)) {
    LssSlave::Callbacks callbacks;
    callbacks.apply_node_id = [this](std::uint8_t id) {
      resets.push_back(id);
      lss->SetActiveNodeId(id);
    };
    lss = std::make_unique<LssSlave>(port, scheduler, address, kLssUnconfigured, 4, std::move(callbacks));
    port.OnReceive([this](const CanFrame& frame, BusTime) { lss->OnFrame(frame); });
  }
  LoopbackPort& port;
  std::unique_ptr<LssSlave> lss;
  std::vector<std::uint8_t> resets;
};

TEST(Fastscan, FindsTwoNonConfiguredSlavesAndAssignsNodeIds) {
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  // Same vendor, product and revision; serial numbers differ in several bits.
  const LssAddress address_a{0x00000055, 0xAA020411, 0x00010000, 0x0000B00A};
  const LssAddress address_b{0x00000055, 0xAA020411, 0x00010000, 0x0000A00B};
  Node a(bus, scheduler, "a", address_a);
  Node b(bus, scheduler, "b", address_b);
  BusProbe probe(bus, "master");
  FastscanMaster master(probe, scheduler);

  // Round 1: offering 0 first, the scan follows the lower serial number: slave b.
  auto found = master.Scan();
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(*found, address_b);
  EXPECT_EQ(b.lss->CurrentMode(), LssSlave::Mode::kConfiguration);
  EXPECT_EQ(a.lss->CurrentMode(), LssSlave::Mode::kWaiting);
  // 1 reset + 4 × (32 bits + 1 confirmation).
  EXPECT_EQ(master.requests(), 1u + 4u * 33u);

  // Only b is in configuration: only b answers configure node-ID and the inquiry.
  probe.Clear();
  probe.Send("7E5#1110000000000000");
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"7E4#1100000000000000"});
  probe.Send("7E5#5D00000000000000");
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"7E4#5D0BA00000000000"});
  probe.Send("7E5#0400000000000000");
  EXPECT_EQ(b.resets, std::vector<std::uint8_t>{0x10});
  EXPECT_TRUE(a.resets.empty());
  EXPECT_EQ(b.lss->ActiveNodeId(), 0x10);

  // Round 2: b is configured now and stays silent; the scan finds a.
  found = master.Scan();
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(*found, address_a);
  probe.Clear();
  probe.Send("7E5#1111000000000000");
  EXPECT_EQ(probe.Take(), std::vector<std::string>{"7E4#1100000000000000"});
  probe.Send("7E5#0400000000000000");
  EXPECT_EQ(a.resets, std::vector<std::uint8_t>{0x11});
  EXPECT_EQ(a.lss->ActiveNodeId(), 0x11);
  EXPECT_EQ(b.lss->ActiveNodeId(), 0x10);

  // Round 3: nobody is left; the reset request is not answered.
  EXPECT_FALSE(master.Scan().has_value());
}

// A slave that drops out in the middle of a part (a different bit) must not re-join later in the
// same round, even when the remaining bits happen to match.
TEST(Fastscan, SlaveDroppedOutOfAPartStaysOutUntilTheNextReset) {
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  const LssAddress address_a{0x00000055, 0xAA020411, 0x00010000, 0x80000001};
  const LssAddress address_b{0x00000055, 0xAA020411, 0x00010000, 0x00000001};
  Node a(bus, scheduler, "a", address_a);
  Node b(bus, scheduler, "b", address_b);
  BusProbe probe(bus, "master");
  FastscanMaster master(probe, scheduler);
  auto found = master.Scan();
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(*found, address_b);
  EXPECT_EQ(a.lss->CurrentMode(), LssSlave::Mode::kWaiting);
  EXPECT_EQ(b.lss->CurrentMode(), LssSlave::Mode::kConfiguration);
}

}  // namespace
}  // namespace canfleet::canopen
