#pragma once
// A running PS-24-24-350W-CAN at its factory node-ID 127 (7Fh, manual UMAX080311 §2.1) on a
// loopback bus with simulated time, and the master's side as frame scripts: "67F#2B..." is an SDO
// request, "5FF#60..." the node's answer, "0FF#..." its EMCY, "27F#..." RPDO1.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "bus/loopback_bus.hpp"
#include "clock/scheduler.hpp"
#include "node/devices/device_node.hpp"
#include "node/devices/power_supply_24v_350w/power_supply.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::devices::test {

using namespace std::chrono_literals;

/// Little-endian hex of the low `size` bytes of `value` ("E803" for 1000, 2 bytes).
std::string LeHex(std::uint64_t value, int size);
/// SDO expedited download request to node 7Fh: "67F#2B" + index + sub + data.
std::string SdoWrite(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size);
/// SDO download confirmation: "5FF#60" + index + sub + 00000000.
std::string SdoWritten(std::uint16_t index, std::uint8_t sub);
/// SDO abort from node 7Fh with `code`.
std::string SdoAborted(std::uint16_t index, std::uint8_t sub, std::uint32_t code);
/// SDO upload request: "67F#40" + index + sub + 00000000.
std::string SdoRead(std::uint16_t index, std::uint8_t sub);
/// EMCY of node 7Fh: code, 1001h, then the family's manufacturer bytes (channel, description).
std::string Emcy(std::uint16_t code, std::uint8_t reg, std::uint8_t channel, std::uint8_t description);
/// The error-reset EMCY with 1001h = `reg`.
std::string EmcyReset(std::uint8_t reg = 0);

class PsTest : public ::testing::Test {
 protected:
  static constexpr std::uint8_t kNodeId = 0x7F;

  explicit PsTest(std::filesystem::path state_dir = {});

  SimulatedIo& io() { return node_.io(); }
  canopen::ObjectDictionary& od() { return node_.od(); }
  canopen::CanopenStack& stack() { return node_.stack(); }
  PowerSupply& ps() { return static_cast<PowerSupply&>(node_.device()); }
  std::string State() { return io().Enum("PS.state"); }

  void Advance(Duration d) { scheduler_.Advance(d); }
  /// NMT start (node 7Fh).
  void Start();
  void Send(std::string_view frame) { master_.Send(frame); }

  /// Every frame received since the last call (frames set aside by Sdo() first).
  std::vector<std::string> Frames();
  /// Of Frames(), those starting with `prefix` ("0FF#" for EMCY, "2FF#" for TPDO2).
  std::vector<std::string> Frames(std::string_view prefix);
  /// Sends an SDO request and returns the node's answer ("" if none); other frames are kept.
  std::string Sdo(std::string_view request);
  void Write(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size);
  std::string TryWrite(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size);
  std::int64_t Read(std::uint16_t index, std::uint8_t sub, bool is_signed = false);
  std::uint32_t Entry(std::uint8_t sub) { return static_cast<std::uint32_t>(Read(0x1003, sub)); }

  void SetNumber(std::string_view name, double value) {
    ASSERT_TRUE(io().SetNumber(name, value).ok()) << name;
  }
  void SetEnum(std::string_view name, std::string_view value) {
    ASSERT_TRUE(io().SetEnum(name, value).ok()) << name;
  }
  void Enable(bool high) { SetEnum("ENABLE.level", high ? "high" : "low"); }
  /// 2100h.1 = 0: 6113h follows the input at the next sample (exact timings in tests).
  void NoInputFilter() { Write(0x2100, 1, 0, 1); }
  /// Switches the output on by CAN (6200h.2 = FDh over SDO) and lets the loop run.
  void OnByCan();

  SimulatedScheduler scheduler_;
  LoopbackBus bus_;
  LoopbackPort& node_port_;
  canfleet::test::BusProbe master_;
  DeviceNode node_;
  std::deque<std::string> backlog_;
};

}  // namespace canfleet::devices::test
