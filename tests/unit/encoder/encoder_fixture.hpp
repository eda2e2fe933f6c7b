#pragma once
// A running AX023241 encoder dual valve controller (node-ID 5) on a loopback bus with simulated
// time, and the master's side as frame scripts: "605#2B..." is an SDO request, "585#60..." the
// node's answer, "085#..." its EMCY, "185#..." its TPDO1.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <deque>
#include <string>
#include <string_view>
#include <vector>

#include "bus/loopback_bus.hpp"
#include "clock/scheduler.hpp"
#include "node/devices/device_node.hpp"
#include "node/devices/encoder_dual_valve/encoder_valve_controller.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::devices::encoder::test {

using namespace std::chrono_literals;

/// Little-endian hex of the low `size` bytes of `value` ("E803" for 1000, 2 bytes).
std::string LeHex(std::uint64_t value, int size);
/// SDO expedited download request to node 5.
std::string SdoWrite(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size);
std::string SdoWritten(std::uint16_t index, std::uint8_t sub);
std::string SdoAborted(std::uint16_t index, std::uint8_t sub, std::uint32_t code);
std::string SdoRead(std::uint16_t index, std::uint8_t sub);
/// EMCY of node 5 in the family's layout: code, 1001h, channel, description, 0, 0, 0.
std::string Emcy(std::uint16_t code, std::uint8_t channel, std::uint8_t description);
/// The bits of a REAL32.
std::uint32_t Real32Bits(float value);

class EncoderTest : public ::testing::Test {
 protected:
  static constexpr std::uint8_t kNodeId = 5;

  EncoderTest();

  SimulatedIo& io() { return node_.io(); }
  canopen::ObjectDictionary& od() { return node_.od(); }
  canopen::CanopenStack& stack() { return node_.stack(); }
  EncoderValveController& device() { return static_cast<EncoderValveController&>(node_.device()); }

  void Advance(Duration d) { scheduler_.Advance(d); }
  /// NMT start of node 5.
  void Start() { Send("000#0105"); }
  void Send(std::string_view frame) { master_.Send(frame); }

  /// Every frame received since the last call (frames set aside by Sdo() first).
  std::vector<std::string> Frames();
  /// Of Frames(), those starting with `prefix`.
  std::vector<std::string> Frames(std::string_view prefix);
  /// Sends an SDO request and returns the node's answer; other frames are kept for Frames().
  std::string Sdo(std::string_view request);
  void Write(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size);
  std::string TryWrite(std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size);
  std::int64_t Read(std::uint16_t index, std::uint8_t sub, bool is_signed = false);
  void SetNumber(std::string_view name, double value) {
    ASSERT_TRUE(io().SetNumber(name, value).ok()) << name;
  }
  void SetEnum(std::string_view name, std::string_view value) {
    ASSERT_TRUE(io().SetEnum(name, value).ok()) << name;
  }
  double Out(std::string_view name) { return io().Number(name); }
  bool On(std::string_view name) { return io().Bool(name); }
  /// TPDO1's 100 ms event timer off.
  void SilenceTpdo1() { Write(0x1800, 5, 0, 2); }

  SimulatedScheduler scheduler_;
  LoopbackBus bus_;
  LoopbackPort& node_port_;
  canfleet::test::BusProbe master_;
  DeviceNode node_;
  std::deque<std::string> backlog_;
};

}  // namespace canfleet::devices::encoder::test
