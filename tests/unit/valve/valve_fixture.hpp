#pragma once
// A running valve controller (node-ID 5) on a loopback bus with simulated time, and the master's
// side as frame scripts: "605#2B..." is an SDO request, "585#60..." the node's answer.

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
#include "node/devices/valve_12in12out/valve_controller.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::devices::valve::test {

using namespace std::chrono_literals;

/// Little-endian hex of the low `size` bytes of `value` ("E803" for 1000, 2 bytes).
std::string LeHex(std::uint64_t value, int size);
/// SDO expedited download request to node 5.
std::string SdoWrite(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size);
/// SDO download confirmation.
std::string SdoWritten(std::uint16_t index, std::uint8_t sub);
/// SDO abort from node 5 with `code`.
std::string SdoAborted(std::uint16_t index, std::uint8_t sub, std::uint32_t code);
/// EMCY of node 5 in the family's layout: code, 1001h, channel, description (family_error_policy.hpp).
std::string Emcy(std::uint16_t code, std::uint8_t reg, std::uint8_t channel, std::uint8_t description);
/// The error reset EMCY (0000h) with the 1001h value after it.
std::string EmcyReset(std::uint8_t reg = 0);

class ValveTest : public ::testing::Test {
 protected:
  static constexpr std::uint8_t kNodeId = 5;

  ValveTest();

  SimulatedIo& io() { return node_.io(); }
  canopen::ObjectDictionary& od() { return node_.od(); }
  canopen::CanopenStack& stack() { return node_.stack(); }
  ValveController& valve() { return static_cast<ValveController&>(node_.device()); }
  LoopbackPort& port() { return node_port_; }

  void Advance(Duration d) { scheduler_.Advance(d); }
  /// NMT start (node 5).
  void Start() { Send("000#0105"); }
  void Send(std::string_view frame) { master_.Send(frame); }

  /// Every frame received since the last call (frames set aside by Sdo() first).
  std::vector<std::string> Frames();
  /// Of Frames(), those starting with `prefix` ("085#" for EMCY).
  std::vector<std::string> Frames(std::string_view prefix);
  /// Sends an SDO request and returns the node's answer; other frames are kept for Frames().
  std::string Sdo(std::string_view request);
  /// Expedited write that must succeed.
  void Write(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size);
  /// Expedited write; the answer (confirmation or abort).
  std::string TryWrite(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size);
  /// Expedited write that must be refused with `code`.
  void Refused(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size, std::uint32_t code);
  /// Expedited read that must succeed; the value, sign-extended for `is_signed`.
  std::int64_t Read(std::uint16_t index, std::uint8_t sub, bool is_signed = false);
  /// A value as the device holds it (no SDO traffic).
  std::int64_t Value(std::uint16_t index, std::uint8_t sub);
  void SetNumber(std::string_view name, double value) {
    ASSERT_TRUE(io().SetNumber(name, value).ok()) << name;
  }
  void SetEnum(std::string_view name, std::string_view value) {
    ASSERT_TRUE(io().SetEnum(name, value).ok()) << name;
  }
  double Out(std::string_view name) { return io().Number(name); }
  /// TPDO1/TPDO2 (100 ms event timers in operational) off, so that scripts see only what they cause.
  void SilenceTpdos();

  SimulatedScheduler scheduler_;
  LoopbackBus bus_;
  LoopbackPort& node_port_;
  canfleet::test::BusProbe master_;
  DeviceNode node_;
  std::deque<std::string> backlog_;
};

}  // namespace canfleet::devices::valve::test
