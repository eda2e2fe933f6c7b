#include "node/devices/encoder_dual_valve/startup_mode.hpp"

#include <chrono>

#include "bus/can_frame.hpp"
#include "node/devices/encoder_dual_valve/encoder_objects.hpp"

namespace canfleet::devices::encoder {

using canopen::NmtState;

StartupMode::StartupMode(Scheduler& scheduler, canopen::ObjectDictionary& od, DevicePort& port)
    : od_(od), port_(port), timer_(scheduler, [this] {
        // CiA 301 §7.2.8.3.1: NMT "start remote node" (01h) to node-ID 0 = all nodes.
        port_.SendFromDevice(CanFrame::Data(0x000, {0x01, 0x00}));
      }) {}

bool StartupMode::StartOperational(const canopen::ObjectDictionary& od) {
  const auto mode = od.GetUnsigned(kStartInOperational, 0);
  return mode == 1 || mode == 2;
}

void StartupMode::OnStateChanged(NmtState state) {
  const bool boot = last_ == NmtState::kInitialising && state != NmtState::kInitialising;
  last_ = state;
  if (state == NmtState::kInitialising) {
    timer_.Cancel();
    return;
  }
  if (boot && od_.GetUnsigned(kStartInOperational, 0) == 2)
    timer_.StartAfter(
        std::chrono::milliseconds(static_cast<std::int64_t>(od_.GetUnsigned(kStartNmtDelay, 0))));
}

}  // namespace canfleet::devices::encoder
