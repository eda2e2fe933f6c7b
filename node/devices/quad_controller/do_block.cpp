#include "node/devices/quad_controller/do_block.hpp"

#include <chrono>
#include <cmath>

namespace canfleet::devices::quad {

DoBlock::DoBlock(canopen::CanopenStack& stack, Scheduler& scheduler, QuadIo& io) : stack_(stack), io_(io) {
  auto& od = stack.od();
  write_state_ = OdRef(od, kDoWriteState, 1);
  polarity_ = OdRef(od, kDoPolarity, 1);
  response_ = OdRef(od, kDoResponse, 1);
  fault_mode_ = OdRef(od, kDoFaultMode, 1);
  fault_state_ = OdRef(od, kDoFaultState, 1);
  read_state_ = OdRef(od, kDoReadState, 1);
  for (int o = 0; o < kDigitalOutputs; ++o) {
    control_[o] = OdRef(od, kDoControlInput, SubOf(o));
    error_delay_[o] = OdRef(od, kDoErrorDelay, SubOf(o));
  }
  for (int n = 0; n < kPouts; ++n) {
    output_type_[n] = OdRef(od, kAoOutputType, SubOf(n));
    measured_current_[n] = OdRef(od, kAoMeasuredCurrent, SubOf(n));
    pout_faults_[n] =
        std::make_unique<LoadFaults>(scheduler, stack, kDescDigitalOutput, SubOf(n), kBehaviourDigitalOutput);
  }
  dout_fault_ = std::make_unique<DelayedFault>(
      scheduler, stack, MakeErrorEntry(kEmcyDigitalOutput, kDescDigitalOutput, SubOf(kDout)),
      kBehaviourDigitalOutput);
}

bool DoBlock::Owns(int pout) const {
  return output_type_[pout].Get() == static_cast<std::int64_t>(OutputType::kDigital);
}

void DoBlock::Reset() {
  previous_control_ = {};
  latch_ = {};
  for (auto& f : pout_faults_)
    f->Reset();
  dout_fault_->Reset();
}

bool DoBlock::Control(int output, const AiBlock& ai, const DiBlock& di) const {
  const auto source = control_[output].Get();
  if (source == kControlCan) return write_state_.Bit(static_cast<unsigned>(output));
  if (source >= 1 && source <= kInputs) return ai.OnOff(static_cast<int>(source - 1));
  if (source >= 11 && source <= 10 + kInputs) {
    const int ch = static_cast<int>(source - 11);
    return ai.Mode(ch) == OperatingMode::kDigital && di.State(ch);
  }
  return false;
}

bool DoBlock::Update(const OutputConditions& conditions, const AiBlock& ai, const DiBlock& di) {
  const auto previous_control = previous_control_;
  const auto latch = latch_;
  bool faults_changed = false;
  std::uint8_t states = 0;
  for (int o = 0; o < kDigitalOutputs; ++o) {
    const auto bit = static_cast<unsigned>(o);
    const bool is_pout = o < kPouts;
    const bool digital = !is_pout || Owns(o);
    const bool control = Control(o, ai, di);
    // Edges are tracked in every mode and state, so a latch toggles only on a real OFF→ON.
    const bool edge = control && !previous_control_[o];
    previous_control_[o] = control;
    if (!digital) {
      latch_[o] = false;
      faults_changed = pout_faults_[o]->Update(false, *io_.pout_load[o], Duration::zero()) || faults_changed;
      continue;
    }
    bool logic;
    if (response_.Bit(bit)) {
      if (edge) latch_[o] = !latch_[o];
      logic = latch_[o];
    } else {
      logic = control != polarity_.Bit(bit);
    }
    bool on = logic;
    if (conditions.Stopped())
      on = false;
    else if (conditions.fault_state && fault_mode_.Bit(bit))
      on = fault_state_.Bit(bit);
    else if (control_[o].Get() == kControlCan && !conditions.CanControlAllowed())
      on = false;
    if (on) states = static_cast<std::uint8_t>(states | (1u << bit));
    Drive(o, on);

    const Duration delay = std::chrono::milliseconds(error_delay_[o].Get());
    if (is_pout)
      faults_changed = pout_faults_[o]->Update(true, *io_.pout_load[o], delay) || faults_changed;
    else
      faults_changed = dout_fault_->Update(!io_.dout_load->Is(kLoadNominal), delay) || faults_changed;
  }
  if (read_state_.Set(states)) stack_.pdo().NotifyChanged(read_state_.sub());
  return faults_changed || previous_control != previous_control_ || latch != latch_;
}

// The load decides what flows: a short trips the driver's protection, an open load draws nothing.
void DoBlock::Drive(int output, bool on) {
  if (output == kDout) {
    io_.io.Publish(*io_.dout_on, on && !io_.dout_load->Is(kLoadShort));
    return;
  }
  const IoSignal& load = *io_.pout_load[output];
  const double current = on && load.Is(kLoadNominal) ? io_.pout_load_current[output]->Number() : 0.0;
  io_.io.Publish(*io_.pout_on[output], on && !load.Is(kLoadShort));
  io_.io.Publish(*io_.pout_current[output], current);
  io_.io.Publish(*io_.pout_dither_amplitude[output], 0.0);
  io_.io.Publish(*io_.pout_dither_frequency[output], 0.0);
  measured_current_[output].Set(std::lround(current));
}

}  // namespace canfleet::devices::quad
