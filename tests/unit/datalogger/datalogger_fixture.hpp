#pragma once
// A running data logger on two loopback buses with simulated time: CAN1 (node 5) and CAN2 (node 6),
// and a master's side on each as frame scripts ("605#40..." an SDO request to CAN1's node,
// "586#4B..." CAN2's node answering).

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "bus/loopback_bus.hpp"
#include "clock/scheduler.hpp"
#include "node/devices/datalogger_tc_analog/datalogger.hpp"
#include "node/devices/device_node.hpp"
#include "tests/support/bus_probe.hpp"
#include "tests/support/sdo_script.hpp"

namespace canfleet::devices::test {

using namespace std::chrono_literals;

using canfleet::test::LeHex;
/// "<cob>#..." with the COB-ID in three hex digits.
std::string Cob(std::uint32_t cob_id);
/// The master's SDO frame scripts of every product fixture (tests/support/sdo_script.hpp), under
/// the names the data logger's tests use.
inline std::string SdoWrite(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint64_t value,
                            int size) {
  return canfleet::test::SdoDownload(node, index, sub, value, size);
}
inline std::string SdoWritten(std::uint8_t node, std::uint16_t index, std::uint8_t sub) {
  return canfleet::test::SdoDownloaded(node, index, sub);
}
inline std::string SdoAborted(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t code) {
  return canfleet::test::SdoAbortFrom(node, index, sub, code);
}
inline std::string SdoRead(std::uint8_t node, std::uint16_t index, std::uint8_t sub) {
  return canfleet::test::SdoUpload(node, index, sub);
}
/// The family's EMCY: code, 1001h, channel, description (family_error_policy.hpp).
std::string Emcy(std::uint8_t node, std::uint16_t code, std::uint8_t reg, std::uint8_t channel,
                 std::uint8_t description);
/// The error-reset EMCY (0000h) with the 1001h left.
std::string EmcyReset(std::uint8_t node, std::uint8_t reg);

class DataLoggerTest : public ::testing::Test {
 protected:
  static constexpr std::uint8_t kNode1 = 5;  ///< CAN1
  static constexpr std::uint8_t kNode2 = 6;  ///< CAN2
  static constexpr std::array<std::uint8_t, 2> kNodes = {kNode1, kNode2};

  explicit DataLoggerTest(std::filesystem::path state_dir = {});
  ~DataLoggerTest() override;

  /// Power-on (again): a new node on the same buses and state directory; drops the boot-ups.
  void Boot();

  DeviceNode& node() { return *node_; }
  DataLogger& logger() { return static_cast<DataLogger&>(node_->device()); }
  SimulatedIo& io() { return node_->io(); }
  canopen::CanopenStack& stack(int port) { return node_->stack(static_cast<std::size_t>(port)); }

  void Advance(Duration d) { scheduler_.Advance(d); }
  /// NMT start of `port`'s node.
  void Start(int port);
  void StartBoth() {
    Start(0);
    Start(1);
  }
  /// A frame from `port`'s master.
  void Send(int port, std::string_view frame) { Probe(port).Send(frame); }

  /// Every frame `port`'s master received since the last call.
  std::vector<std::string> Frames(int port);
  /// Of Frames(port), those starting with `prefix`.
  std::vector<std::string> Frames(int port, std::string_view prefix);
  /// An SDO request on `port`; the node's answer (other frames kept for Frames()).
  std::string Sdo(int port, std::string_view request);
  void Write(int port, std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size);
  std::string TryWrite(int port, std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size);
  std::int64_t Read(int port, std::uint16_t index, std::uint8_t sub, bool is_signed = false);
  /// 1003h of `port` as its entries, newest first.
  std::vector<std::uint32_t> ErrorField(int port);

  void SetNumber(std::string_view name, double value) {
    ASSERT_TRUE(io().SetNumber(name, value).ok()) << name;
  }
  void SetBool(std::string_view name, bool value) { ASSERT_TRUE(io().SetBool(name, value).ok()) << name; }
  void SetEnum(std::string_view name, std::string_view value) {
    ASSERT_TRUE(io().SetEnum(name, value).ok()) << name;
  }

  /// What the demo topology sets (README "Factory thresholds"): the TC limits of 2170h-2173h to
  /// -40.0 / 600.0 / -50.0 / 700.0 C on all four channels, then waits for the flags to clear and
  /// drops the frames that caused.
  void ConfigureTcLimitsAway();
  /// TPDO1-3 event timers 0 on both ports (only the test's own frames remain).
  void SilenceTpdos();

  canfleet::test::BusProbe& Probe(int port) { return port == 0 ? can1_ : can2_; }

  std::filesystem::path state_dir_;
  SimulatedScheduler scheduler_;
  LoopbackBus bus1_, bus2_;
  LoopbackPort& port1_;
  LoopbackPort& port2_;
  canfleet::test::BusProbe can1_;
  canfleet::test::BusProbe can2_;
  std::unique_ptr<DeviceNode> node_;
  std::array<std::deque<std::string>, 2> backlog_;
};

/// The same with a state directory (storage tests); removed afterwards.
class DataLoggerStorageTest : public DataLoggerTest {
 protected:
  DataLoggerStorageTest();
  ~DataLoggerStorageTest() override;
  static std::filesystem::path MakeDir();
};

}  // namespace canfleet::devices::test
