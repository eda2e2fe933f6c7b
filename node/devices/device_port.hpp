#pragma once
/// @file The port a device's stack runs on: the node's real BusPort with two device hooks between
/// them (framework issue, point 7). A device may
///   - see every received frame before the stack does (the power supply's sleep wakes on any CAN
///     frame, manual UMAX080311 §1.4), and
///   - mute its own transmissions (asleep, the supply sends nothing), and
///   - send a frame itself (the encoder's start-up mode 2 sends NMT Start, AX023241 5555h).
/// The stack never knows the difference: it is still one BusPort (design decision 1).

#include <functional>

#include "bus/bus_port.hpp"

namespace canfleet::devices {

class DevicePort final : public BusPort {
 public:
  /// Called for every received frame before the stack sees it.
  using FrameObserver = std::function<void(const CanFrame&)>;

  explicit DevicePort(BusPort& port);
  ~DevicePort() override;
  DevicePort(const DevicePort&) = delete;
  DevicePort& operator=(const DevicePort&) = delete;

  /// The stack's transmissions: dropped while muted (returns false, as a controller that is off).
  bool Send(const CanFrame& frame) override;
  ControllerState State() const override { return port_.State(); }
  bool SetBitRate(std::uint32_t bit_per_s) override { return port_.SetBitRate(bit_per_s); }
  void AcceptanceMayHaveChanged() override { port_.AcceptanceMayHaveChanged(); }

  /// A frame the device sends itself (not muted: the device decides when it speaks).
  bool SendFromDevice(const CanFrame& frame) { return port_.Send(frame); }
  void SetMuted(bool muted) { muted_ = muted; }
  bool Muted() const { return muted_; }
  /// `wanted`: whether the observer needs every frame now (empty: always). A frame the stack does
  /// not listen to then still reaches the port (its acceptance filter lets every frame through).
  void ObserveFrames(FrameObserver observer, std::function<bool()> wanted = {}) {
    observer_ = std::move(observer);
    wanted_ = std::move(wanted);
  }
  /// The device watches every frame now (a power supply asleep wakes on any of them, §1.2.2).
  bool Observed() const { return observer_ && (!wanted_ || wanted_()); }

 private:
  BusPort& port_;
  FrameObserver observer_;
  std::function<bool()> wanted_;
  bool muted_ = false;
};

}  // namespace canfleet::devices
