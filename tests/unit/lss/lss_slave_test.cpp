// The CiA 305 v3.0.0 LSS slave, service by service, as frame scripts on a loopback bus. Figure
// numbers are CiA 305 v3.0.0's. The slave under test has the LSS address
// vendor 00000055h, product AA020411h, revision 00010000h, serial 12345678h.
#include "node/canopen/lss/lss_slave.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <vector>

#include "tests/support/bus_probe.hpp"

namespace canfleet::canopen {
namespace {

using namespace std::chrono_literals;
using test::BusProbe;
using test::Frame;

constexpr LssAddress kAddress{0x00000055, 0xAA020411, 0x00010000, 0x12345678};

class LssSlaveTest : public ::testing::Test {
 protected:
  LssSlaveTest() : port_(bus_.Attach("slave")), probe_(bus_) {
    port_.OnReceive([this](const CanFrame& frame, BusTime) {
      if (slave_) slave_->OnFrame(frame);
    });
  }

  /// Creates the slave; `with_store` false leaves store_configuration empty (not supported).
  void Start(std::uint8_t node_id, bool with_store = true) {
    LssSlave::Callbacks callbacks;
    // Like the stack: reset communication with the new ID, then report it back.
    callbacks.apply_node_id = [this](std::uint8_t id) {
      applied_.push_back(id);
      slave_->SetActiveNodeId(id);
    };
    if (with_store) {
      callbacks.store_configuration = [this](std::uint8_t id, std::uint8_t timing) {
        stored_.emplace_back(id, timing);
        return store_ok_;
      };
    }
    callbacks.activate_bit_timing = [this](std::uint8_t timing) {
      activated_.emplace_back(timing, scheduler_.Now().time_since_epoch());
    };
    slave_ = std::make_unique<LssSlave>(port_, scheduler_, kAddress, node_id, 4, std::move(callbacks));
  }

  /// Sends a request and returns every reply it caused (in candump notation).
  std::vector<std::string> Ask(std::string_view request) {
    probe_.Clear();
    probe_.Send(request);
    return probe_.Take();
  }

  void EnterConfiguration() {
    EXPECT_TRUE(Ask("7E5#0401000000000000").empty());
    ASSERT_EQ(slave_->CurrentMode(), LssSlave::Mode::kConfiguration);
  }

  using Replies = std::vector<std::string>;

  SimulatedScheduler scheduler_;
  LoopbackBus bus_;
  LoopbackPort& port_;
  BusProbe probe_;
  std::unique_ptr<LssSlave> slave_;
  std::vector<std::uint8_t> applied_;
  std::vector<std::pair<std::uint8_t, std::uint8_t>> stored_;
  std::vector<std::pair<std::uint8_t, Duration>> activated_;
  bool store_ok_ = true;
};

// CiA 305 fig. 31: switch state global is unconfirmed; 01h = configuration, 00h = waiting.
TEST_F(LssSlaveTest, SwitchStateGlobalChangesModeWithoutReply) {
  Start(5);
  EXPECT_EQ(slave_->CurrentMode(), LssSlave::Mode::kWaiting);
  EXPECT_EQ(Ask("7E5#0401000000000000"), Replies{});
  EXPECT_EQ(slave_->CurrentMode(), LssSlave::Mode::kConfiguration);
  EXPECT_EQ(Ask("7E5#0402000000000000"), Replies{});  // reserved mode value: ignored
  EXPECT_EQ(slave_->CurrentMode(), LssSlave::Mode::kConfiguration);
  EXPECT_EQ(Ask("7E5#0400000000000000"), Replies{});
  EXPECT_EQ(slave_->CurrentMode(), LssSlave::Mode::kWaiting);
  EXPECT_TRUE(applied_.empty());  // node-ID unchanged: no reset
}

// CiA 305 fig. 37–41: inquire identity and node-ID answer with the same cs, value LE in bytes 1–4.
TEST_F(LssSlaveTest, InquireServicesAnswerByteExactInConfiguration) {
  Start(5);
  EnterConfiguration();
  EXPECT_EQ(Ask("7E5#5A00000000000000"), Replies{"7E4#5A55000000000000"});
  EXPECT_EQ(Ask("7E5#5B00000000000000"), Replies{"7E4#5B110402AA000000"});
  EXPECT_EQ(Ask("7E5#5C00000000000000"), Replies{"7E4#5C00000100000000"});
  EXPECT_EQ(Ask("7E5#5D00000000000000"), Replies{"7E4#5D78563412000000"});
  EXPECT_EQ(Ask("7E5#5E00000000000000"), Replies{"7E4#5E05000000000000"});
}

// CiA 305: configuration and inquiry services are not answered in waiting mode.
TEST_F(LssSlaveTest, ConfigurationAndInquiryServicesAreIgnoredInWaiting) {
  Start(5);
  for (const char* request : {"7E5#5A00000000000000", "7E5#5E00000000000000", "7E5#110A000000000000",
                              "7E5#1300020000000000", "7E5#1700000000000000", "7E5#1564000000000000"}) {
    EXPECT_EQ(Ask(request), Replies{}) << request;
  }
  EXPECT_EQ(slave_->PendingNodeId(), 5);
  EXPECT_EQ(slave_->PendingBitTimingIndex(), 4);
  EXPECT_FALSE(slave_->SwitchingBitTiming());
  EXPECT_TRUE(stored_.empty());
}

// CiA 305 fig. 41: a non-configured slave reports node-ID FFh.
TEST_F(LssSlaveTest, InquireNodeIdOfNonConfiguredSlaveIsFF) {
  Start(kLssUnconfigured);
  EnterConfiguration();
  EXPECT_EQ(Ask("7E5#5E00000000000000"), Replies{"7E4#5EFF000000000000"});
}

// CiA 305 fig. 33: 1..127 and FFh are accepted (error 0) as the *pending* ID; 0 and 80h..FEh
// give error 1 (out of range). The active ID does not change yet.
TEST_F(LssSlaveTest, ConfigureNodeIdSetsPendingIdOrAnswersOutOfRange) {
  Start(5);
  EnterConfiguration();
  EXPECT_EQ(Ask("7E5#110A000000000000"), Replies{"7E4#1100000000000000"});
  EXPECT_EQ(slave_->PendingNodeId(), 0x0A);
  EXPECT_EQ(slave_->ActiveNodeId(), 5);
  EXPECT_EQ(Ask("7E5#5E00000000000000"), Replies{"7E4#5E05000000000000"});  // still the active one
  EXPECT_EQ(Ask("7E5#1100000000000000"), Replies{"7E4#1101000000000000"});
  EXPECT_EQ(Ask("7E5#1180000000000000"), Replies{"7E4#1101000000000000"});
  EXPECT_EQ(Ask("7E5#11FE000000000000"), Replies{"7E4#1101000000000000"});
  EXPECT_EQ(slave_->PendingNodeId(), 0x0A);  // refused values leave the pending ID alone
  EXPECT_EQ(Ask("7E5#117F000000000000"), Replies{"7E4#1100000000000000"});
  EXPECT_EQ(Ask("7E5#11FF000000000000"), Replies{"7E4#1100000000000000"});
  EXPECT_EQ(slave_->PendingNodeId(), 0xFF);
}

// CiA 305 fig. 31 with the manuals: "On switch state global to waiting the module resets itself
// back to pre-operational" with the new node-ID.
TEST_F(LssSlaveTest, SwitchingToWaitingAppliesAChangedPendingNodeId) {
  Start(5);
  EnterConfiguration();
  EXPECT_EQ(Ask("7E5#1120000000000000"), Replies{"7E4#1100000000000000"});
  EXPECT_TRUE(applied_.empty());
  EXPECT_EQ(Ask("7E5#0400000000000000"), Replies{});
  EXPECT_EQ(applied_, std::vector<std::uint8_t>{0x20});
  EXPECT_EQ(slave_->ActiveNodeId(), 0x20);
  EXPECT_EQ(slave_->PendingNodeId(), 0x20);
  EXPECT_EQ(slave_->CurrentMode(), LssSlave::Mode::kWaiting);
  // Again to waiting, nothing pending: no second reset.
  EXPECT_EQ(Ask("7E5#0400000000000000"), Replies{});
  EXPECT_EQ(applied_.size(), 1u);
}

TEST_F(LssSlaveTest, ReconfiguringTheSameNodeIdDoesNotReset) {
  Start(5);
  EnterConfiguration();
  EXPECT_EQ(Ask("7E5#1105000000000000"), Replies{"7E4#1100000000000000"});
  EXPECT_EQ(Ask("7E5#0400000000000000"), Replies{});
  EXPECT_TRUE(applied_.empty());
}

// A configured node can be made non-configured again (configure node-ID FFh, CiA 305 fig. 33).
TEST_F(LssSlaveTest, ConfiguringFFThenWaitingUnconfiguresTheNode) {
  Start(5);
  EnterConfiguration();
  EXPECT_EQ(Ask("7E5#11FF000000000000"), Replies{"7E4#1100000000000000"});
  EXPECT_EQ(Ask("7E5#0400000000000000"), Replies{});
  EXPECT_EQ(applied_, std::vector<std::uint8_t>{0xFF});
  EXPECT_EQ(slave_->ActiveNodeId(), kLssUnconfigured);
}

// CiA 305 fig. 34: table 0 (CiA 301) indexes 0–4 and 6–8; reserved 5, auto 9 and other tables: error 1.
TEST_F(LssSlaveTest, ConfigureBitTimingAcceptsTheCia301TableOnly) {
  Start(5);
  EnterConfiguration();
  EXPECT_EQ(Ask("7E5#1300020000000000"), Replies{"7E4#1300000000000000"});
  EXPECT_EQ(slave_->PendingBitTimingIndex(), 2);
  EXPECT_EQ(slave_->ActiveBitTimingIndex(), 4);  // only activate bit timing switches
  EXPECT_EQ(Ask("7E5#1300050000000000"), Replies{"7E4#1301000000000000"});
  EXPECT_EQ(Ask("7E5#1300090000000000"), Replies{"7E4#1301000000000000"});
  EXPECT_EQ(Ask("7E5#1300FF0000000000"), Replies{"7E4#1301000000000000"});
  EXPECT_EQ(Ask("7E5#1301000000000000"), Replies{"7E4#1301000000000000"});
  EXPECT_EQ(slave_->PendingBitTimingIndex(), 2);
  for (int index : {0, 1, 3, 4, 6, 7, 8}) {
    char request[32];
    std::snprintf(request, sizeof request, "7E5#1300%02X0000000000", index);
    EXPECT_EQ(Ask(request), Replies{"7E4#1300000000000000"}) << index;
  }
}

// CiA 305 fig. 35: no reply; wait the switch delay, switch, wait the delay again. Requests in
// between are not answered. The example delay of the manuals is 15 88 13 = 5000 ms.
TEST_F(LssSlaveTest, ActivateBitTimingSwitchesAfterOneDelayAndIsSilentForTwo) {
  Start(5);
  EnterConfiguration();
  EXPECT_EQ(Ask("7E5#1300030000000000"), Replies{"7E4#1300000000000000"});
  EXPECT_EQ(Ask("7E5#1588130000000000"), Replies{});
  EXPECT_TRUE(slave_->SwitchingBitTiming());
  scheduler_.Advance(4999ms);
  EXPECT_TRUE(activated_.empty());
  EXPECT_EQ(Ask("7E5#5E00000000000000"), Replies{});  // silent before the switch
  scheduler_.Advance(1ms);
  ASSERT_EQ(activated_.size(), 1u);
  EXPECT_EQ(activated_[0], std::make_pair(std::uint8_t{3}, Duration(5000ms)));
  EXPECT_EQ(slave_->ActiveBitTimingIndex(), 3);
  scheduler_.Advance(4999ms);
  EXPECT_TRUE(slave_->SwitchingBitTiming());
  EXPECT_EQ(Ask("7E5#5E00000000000000"), Replies{});  // silent after the switch
  scheduler_.Advance(1ms);
  EXPECT_FALSE(slave_->SwitchingBitTiming());
  EXPECT_EQ(Ask("7E5#5E00000000000000"), Replies{"7E4#5E05000000000000"});
  EXPECT_EQ(activated_.size(), 1u);
  EXPECT_EQ(scheduler_.ArmedCount(), 0u);
}

// CiA 305 fig. 36: store configuration persists the pending node-ID and bit timing; error 0 ok,
// 1 not supported, 2 storage access error. As in the manuals' baud-rate walk-through, store
// follows activate bit timing and is answered on the new rate.
TEST_F(LssSlaveTest, StoreConfigurationPersistsPendingValues) {
  Start(5);
  EnterConfiguration();
  EXPECT_EQ(Ask("7E5#1130000000000000"), Replies{"7E4#1100000000000000"});
  EXPECT_EQ(Ask("7E5#1300020000000000"), Replies{"7E4#1300000000000000"});
  EXPECT_EQ(Ask("7E5#1564000000000000"), Replies{});
  scheduler_.Advance(200ms);
  EXPECT_EQ(Ask("7E5#1700000000000000"), Replies{"7E4#1700000000000000"});
  EXPECT_EQ(stored_, (std::vector<std::pair<std::uint8_t, std::uint8_t>>{{0x30, 2}}));
  store_ok_ = false;
  EXPECT_EQ(Ask("7E5#1700000000000000"), Replies{"7E4#1702000000000000"});
}

TEST_F(LssSlaveTest, StoreConfigurationWithoutStorageIsNotSupported) {
  Start(5, /*with_store=*/false);
  EnterConfiguration();
  EXPECT_EQ(Ask("7E5#1700000000000000"), Replies{"7E4#1701000000000000"});
}

// CiA 305 fig. 32: the four parts in order; 44h and configuration only if all four match.
TEST_F(LssSlaveTest, SwitchStateSelectiveNeedsAllFourPartsInOrder) {
  Start(5);
  EXPECT_EQ(Ask("7E5#4055000000000000"), Replies{});
  EXPECT_EQ(Ask("7E5#41110402AA000000"), Replies{});
  EXPECT_EQ(Ask("7E5#4200000100000000"), Replies{});
  EXPECT_EQ(Ask("7E5#4378563412000000"), Replies{"7E4#4400000000000000"});
  EXPECT_EQ(slave_->CurrentMode(), LssSlave::Mode::kConfiguration);
  EXPECT_EQ(Ask("7E5#5D00000000000000"), Replies{"7E4#5D78563412000000"});
}

TEST_F(LssSlaveTest, SwitchStateSelectiveIgnoresAnyMismatchOrOrderError) {
  Start(5);
  // Serial differs in the last bit.
  for (const char* r : {"7E5#4055000000000000", "7E5#41110402AA000000", "7E5#4200000100000000"})
    Ask(r);
  EXPECT_EQ(Ask("7E5#4379563412000000"), Replies{});
  // Product differs: the correct serial afterwards must not complete the selection.
  for (const char* r : {"7E5#4055000000000000", "7E5#41120402AA000000", "7E5#4200000100000000"})
    Ask(r);
  EXPECT_EQ(Ask("7E5#4378563412000000"), Replies{});
  // Revision skipped.
  for (const char* r : {"7E5#4055000000000000", "7E5#41110402AA000000"})
    Ask(r);
  EXPECT_EQ(Ask("7E5#4378563412000000"), Replies{});
  // Serial alone.
  EXPECT_EQ(Ask("7E5#4378563412000000"), Replies{});
  EXPECT_EQ(slave_->CurrentMode(), LssSlave::Mode::kWaiting);
}

// CiA 305 fig. 42/43: vendor and product exact, revision and serial within inclusive ranges.
TEST_F(LssSlaveTest, IdentifyRemoteSlaveMatchesRanges) {
  Start(5);
  auto identify = [&](std::uint32_t rev_lo, std::uint32_t rev_hi, std::uint32_t ser_lo,
                      std::uint32_t ser_hi) {
    probe_.Clear();
    probe_.Send(LssFrame32(0x7E5, LssCs::kIdentifyRemoteVendor, 0x55));
    probe_.Send(LssFrame32(0x7E5, LssCs::kIdentifyRemoteProduct, 0xAA020411));
    probe_.Send(LssFrame32(0x7E5, LssCs::kIdentifyRemoteRevisionLow, rev_lo));
    probe_.Send(LssFrame32(0x7E5, LssCs::kIdentifyRemoteRevisionHigh, rev_hi));
    probe_.Send(LssFrame32(0x7E5, LssCs::kIdentifyRemoteSerialLow, ser_lo));
    probe_.Send(LssFrame32(0x7E5, LssCs::kIdentifyRemoteSerialHigh, ser_hi));
    return probe_.Take();
  };
  EXPECT_EQ(identify(0, 0xFFFFFFFF, 0, 0xFFFFFFFF), Replies{"7E4#4F00000000000000"});
  EXPECT_EQ(identify(0x00010000, 0x00010000, 0x12345678, 0x12345678), Replies{"7E4#4F00000000000000"});
  EXPECT_EQ(identify(0, 0xFFFFFFFF, 0x12345679, 0xFFFFFFFF), Replies{});  // serial below range
  EXPECT_EQ(identify(0, 0xFFFFFFFF, 0, 0x12345677), Replies{});           // serial above range
  EXPECT_EQ(identify(0x00010001, 0xFFFFFFFF, 0, 0xFFFFFFFF), Replies{});  // revision below range
  EXPECT_EQ(identify(0, 0x0000FFFF, 0, 0xFFFFFFFF), Replies{});           // revision above range
  EXPECT_EQ(slave_->CurrentMode(), LssSlave::Mode::kWaiting);             // identification does not switch
  // Works in configuration mode too; the wrong vendor never matches.
  EnterConfiguration();
  EXPECT_EQ(identify(0, 0xFFFFFFFF, 0, 0xFFFFFFFF), Replies{"7E4#4F00000000000000"});
  EXPECT_EQ(Ask("7E5#4656000000000000"), Replies{});
  EXPECT_EQ(Ask("7E5#4B FFFFFFFF 000000"), Replies{});  // the last part alone is not a match
}

// CiA 305 fig. 44/45: only a slave without active or pending node-ID answers 50h.
TEST_F(LssSlaveTest, IdentifyNonConfiguredRemoteSlave) {
  Start(kLssUnconfigured);
  EXPECT_EQ(Ask("7E5#4C00000000000000"), Replies{"7E4#5000000000000000"});
  EnterConfiguration();
  EXPECT_EQ(Ask("7E5#4C00000000000000"), Replies{"7E4#5000000000000000"});
  EXPECT_EQ(Ask("7E5#1107000000000000"), Replies{"7E4#1100000000000000"});
  EXPECT_EQ(Ask("7E5#4C00000000000000"), Replies{});  // an ID is pending: already handled
}

TEST_F(LssSlaveTest, ConfiguredSlaveDoesNotAnswerIdentifyNonConfigured) {
  Start(5);
  EXPECT_EQ(Ask("7E5#4C00000000000000"), Replies{});
}

// CiA 305 fig. 46: bit-checked 80h resets every non-configured slave, which answers 4Fh.
TEST_F(LssSlaveTest, FastscanResetIsAnsweredOnlyByNonConfiguredSlavesInWaiting) {
  Start(kLssUnconfigured);
  EXPECT_EQ(Ask("7E5#5100000000800000"), Replies{"7E4#4F00000000000000"});
  // Vendor 00000055h: bits 31..8 are 0, so checking bit 8 with all-zero IDNumber matches ...
  EXPECT_EQ(Ask("7E5#5100000000080000"), Replies{"7E4#4F00000000000000"});
  // ... and checking bit 6 (01010101b has bit 6 set) does not.
  EXPECT_EQ(Ask("7E5#5100000000060000"), Replies{});
  // Wrong LSSSub for the current position, BitChecked 32..7Fh, LSSSub > 3: ignored.
  EXPECT_EQ(Ask("7E5#5100000000080100"), Replies{});
  EXPECT_EQ(Ask("7E5#5100000000200000"), Replies{});
  EXPECT_EQ(Ask("7E5#5100000000080400"), Replies{});
  EnterConfiguration();
  EXPECT_EQ(Ask("7E5#5100000000800000"), Replies{});
}

TEST_F(LssSlaveTest, FastscanIsIgnoredByConfiguredSlaves) {
  Start(5);
  EXPECT_EQ(Ask("7E5#5100000000800000"), Replies{});
}

// CiA 305: LSS frames have DLC 8; anything else is dropped. Only 7E5h belongs to the slave.
TEST_F(LssSlaveTest, OnlyEightByteFramesOn7E5AreServed) {
  Start(5);
  EXPECT_EQ(Ask("7E5#0401"), Replies{});
  EXPECT_EQ(slave_->CurrentMode(), LssSlave::Mode::kWaiting);
  EXPECT_EQ(Ask("7E5#04010000000000"), Replies{});
  EXPECT_EQ(slave_->CurrentMode(), LssSlave::Mode::kWaiting);
  EXPECT_EQ(Ask("7E5#R8"), Replies{});
  EXPECT_TRUE(slave_->OnFrame(Frame("7E5#0401")));
  EXPECT_TRUE(slave_->OnFrame(Frame("7E5#R")));
  EXPECT_FALSE(slave_->OnFrame(Frame("7E4#4F00000000000000")));
  EXPECT_FALSE(slave_->OnFrame(Frame("605#4000100000000000")));
  EXPECT_FALSE(slave_->OnFrame(Frame("000007E5#0401000000000000")));  // 29-bit: not LSS
  EXPECT_EQ(slave_->CurrentMode(), LssSlave::Mode::kWaiting);
  EXPECT_TRUE(slave_->OnFrame(Frame("7E5#0401000000000000")));
  EXPECT_EQ(slave_->CurrentMode(), LssSlave::Mode::kConfiguration);
  EXPECT_EQ(Ask("7E5#EE00000000000000"), Replies{});  // unknown cs
}

// Nothing a master sends may wedge the slave: every command specifier with random payloads, in
// both modes; afterwards the slave still answers.
TEST_F(LssSlaveTest, ArbitraryRequestsNeverWedgeTheSlave) {
  Start(kLssUnconfigured);
  std::uint32_t seed = 12345;
  auto next = [&seed] {
    seed = seed * 1103515245u + 12345u;
    return static_cast<std::uint8_t>(seed >> 16);
  };
  for (int i = 0; i < 20000; ++i) {
    CanFrame frame;
    frame.id = 0x7E5;
    frame.dlc = 8;
    for (auto& b : frame.data)
      b = next();
    // Keep the delays short so the run stays in simulated milliseconds.
    if (frame.data[0] == 0x15) frame.data[2] = 0;
    probe_.Send(frame);
    scheduler_.Advance(1ms);
  }
  scheduler_.Advance(1s);
  EXPECT_FALSE(slave_->SwitchingBitTiming());
  Ask("7E5#0401000000000000");
  EXPECT_EQ(slave_->CurrentMode(), LssSlave::Mode::kConfiguration);
  EXPECT_EQ(Ask("7E5#5A00000000000000"), Replies{"7E4#5A55000000000000"});
}

}  // namespace
}  // namespace canfleet::canopen
