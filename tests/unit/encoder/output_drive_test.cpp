// The output drive model of the AX023241 (1.4 Tables 8-12, Figure 5, 1.5, 4.3), without objects:
// ramps, control fault responses, override, enable, digital delay, hotshot, the driver's electrical
// limits and its short-circuit protection with retries.
#include <gtest/gtest.h>

#include "node/devices/encoder_dual_valve/output_drive.hpp"

namespace canfleet::devices::encoder::test {
namespace {

using Ms = OutputDrive::Ms;

blocks::Signal Ranged(double value, double min, double max) {
  blocks::Signal s;
  s.value = value;
  s.min = min;
  s.max = max;
  return s;
}

DriveCommand Controlled(double value) {
  DriveCommand c;
  c.control.used = true;
  c.control.signal = Ranged(value, 0, 5000);
  return c;
}

DriveSource Constant(bool on) {
  DriveSource s;
  s.used = true;
  s.signal = blocks::Signal::Constant(on ? 1.0 : 0.0);
  return s;
}

// 1.4: "the step size of the output change will be determined by taking the absolute value of the
// output range and dividing it by the ramp time": 5000 mA / 1000 ms = 5 mA per ms. A ramp that was
// idle starts when its target changes; it sleeps again at the target.
TEST(OutputDriveTest, RampsUpAndDownAtTheRangeOverTheRampTime) {
  OutputDrive drive;
  DriveConfig config;
  LoadModel load;
  drive.Step(Ms{500}, config, Controlled(1000), load);
  EXPECT_EQ(drive.Output().target_fv, 1000);
  EXPECT_EQ(drive.Output().current_mA, 5);
  EXPECT_EQ(drive.NextChange(), Ms{1});
  drive.Step(Ms{99}, config, Controlled(1000), load);
  EXPECT_EQ(drive.Output().current_mA, 500);
  drive.Step(Ms{200}, config, Controlled(1000), load);
  EXPECT_EQ(drive.Output().current_mA, 1000);
  EXPECT_FALSE(drive.NextChange());
  config.ramp_down_ms = 0;
  drive.Step(Ms{1}, config, Controlled(0), load);
  EXPECT_EQ(drive.Output().current_mA, 0);
  EXPECT_FALSE(drive.Output().on);
}

// Figure 7: the FV limits 7321h/7323h hold the drive; Table 8: current at most 2500 mA; the supply
// can only push Vps / R through the coil (24 V / 20 ohm = 1200 mA).
TEST(OutputDriveTest, TargetIsHeldToTheLimitsAndTheSupply) {
  OutputDrive drive;
  DriveConfig config;
  config.ramp_up_ms = config.ramp_down_ms = 0;
  LoadModel load;
  drive.Step(Ms{1}, config, Controlled(4000), load);
  EXPECT_EQ(drive.Output().target_fv, 2500);
  EXPECT_EQ(drive.Output().current_mA, 2500);
  EXPECT_DOUBLE_EQ(drive.Output().voltage_V, 20.0);
  load.resistance_ohm = 20;
  drive.Step(Ms{1}, config, Controlled(2000), load);
  EXPECT_EQ(drive.Output().desired_mA, 2000);
  EXPECT_EQ(drive.Output().current_mA, 1200);
  EXPECT_EQ(drive.Output().duty_pct, 100);
  config.fv_min = 300;
  config.fv_max = 1500;
  drive.Step(Ms{1}, config, Controlled(0), load);
  EXPECT_EQ(drive.Output().target_fv, 300);
}

// Table 12 through 6340h: 0 shut off, 1 apply the fault value 7341h, 2 hold the last value.
TEST(OutputDriveTest, ControlFaultResponses) {
  DriveConfig config;
  config.ramp_up_ms = 0;
  LoadModel load;
  DriveCommand faulted = Controlled(1000);
  faulted.control.signal.error = true;
  for (const std::uint8_t response : {std::uint8_t{0}, std::uint8_t{1}, std::uint8_t{2}}) {
    OutputDrive drive;
    config.fault_response = response;
    drive.Step(Ms{1}, config, Controlled(1000), load);
    ASSERT_EQ(drive.Output().current_mA, 1000);
    drive.Step(Ms{1}, config, faulted, load);
    const double expected = response == 0 ? 0.0 : response == 1 ? 500.0 : 1000.0;
    EXPECT_EQ(drive.Output().current_mA, expected) << int(response);
  }
}

// Table 11: override when On (0) or when Off (1) drives 2300h; Table 10 option 0: an enable input
// that is Off shuts the output off at once.
TEST(OutputDriveTest, OverrideAndEnable) {
  OutputDrive drive;
  DriveConfig config;
  config.ramp_up_ms = config.ramp_down_ms = 0;
  config.override_fv = 700;
  LoadModel load;
  DriveCommand command = Controlled(1000);
  command.override_input = Constant(true);
  drive.Step(Ms{1}, config, command, load);
  EXPECT_EQ(drive.Output().current_mA, 700);
  config.override_when_off = true;
  drive.Step(Ms{1}, config, command, load);
  EXPECT_EQ(drive.Output().current_mA, 1000);
  command.enable = Constant(false);
  drive.Step(Ms{1}, config, command, load);
  EXPECT_EQ(drive.Output().current_mA, 0);
  command.enable = Constant(true);
  drive.Step(Ms{1}, config, command, load);
  EXPECT_EQ(drive.Output().current_mA, 1000);
}

// 2224h/2225h: the edge 2225h names is delayed by 2224h ms; the other is immediate.
TEST(OutputDriveTest, DigitalDelayOnTheConfiguredEdge) {
  OutputDrive drive;
  DriveConfig config;
  config.type = OutputType::kDigital;
  config.fv_max = 1;
  config.delay_ms = 300;
  config.delay_on_edge = true;
  LoadModel load;
  DriveCommand command = Controlled(1);
  command.control.signal = Ranged(1, 0, 1);
  drive.Step(Ms{1}, config, command, load);
  EXPECT_FALSE(drive.Output().on);
  EXPECT_EQ(drive.Output().target_fv, 1);
  EXPECT_EQ(drive.NextChange(), Ms{300});
  drive.Step(Ms{299}, config, command, load);
  EXPECT_FALSE(drive.Output().on);
  drive.Step(Ms{1}, config, command, load);
  EXPECT_TRUE(drive.Output().on);
  EXPECT_DOUBLE_EQ(drive.Output().current_mA, 3000.0);  // 24 V / 8 ohm
  command.control.signal = Ranged(0, 0, 1);
  drive.Step(Ms{1}, config, command, load);
  EXPECT_FALSE(drive.Output().on);
}

// Figure 5: hotshot current for the hotshot time after each OFF->ON, then the hold current.
TEST(OutputDriveTest, HotshotThenHold) {
  OutputDrive drive;
  DriveConfig config;
  config.type = OutputType::kHotshot;
  config.fv_max = 1;
  LoadModel load;
  DriveCommand command = Controlled(1);
  command.control.signal = Ranged(1, 0, 1);
  drive.Step(Ms{1}, config, command, load);
  EXPECT_EQ(drive.Output().current_mA, 2000);
  EXPECT_TRUE(drive.Output().hotshot);
  EXPECT_EQ(drive.NextChange(), Ms{1000});
  drive.Step(Ms{1000}, config, command, load);
  EXPECT_EQ(drive.Output().current_mA, 500);
  EXPECT_FALSE(drive.Output().hotshot);
  EXPECT_FALSE(drive.NextChange());
}

// 1.5 and 4.3: a dead short (or a switched load drawing more than 4 A) trips the driver; it is
// re-engaged every 1000 ms while commanded and resumes once the short is gone. An open load keeps
// being driven with no current.
TEST(OutputDriveTest, ShortCircuitProtectionRetriesAndOpenLoadKeepsDriving) {
  OutputDrive drive;
  DriveConfig config;
  config.ramp_up_ms = 0;
  LoadModel load;
  load.load = LoadState::kShort;
  drive.Step(Ms{1}, config, Controlled(1000), load);
  EXPECT_TRUE(drive.Output().tripped);
  EXPECT_FALSE(drive.Output().on);
  EXPECT_EQ(drive.NextChange(), Ms{1000});
  drive.Step(Ms{1000}, config, Controlled(1000), load);
  EXPECT_TRUE(drive.Output().tripped);  // tried again, still shorted
  load.load = LoadState::kNominal;
  drive.Step(Ms{400}, config, Controlled(1000), load);
  EXPECT_TRUE(drive.Output().tripped);  // waits for the next retry
  drive.Step(Ms{600}, config, Controlled(1000), load);
  EXPECT_FALSE(drive.Output().tripped);
  EXPECT_EQ(drive.Output().current_mA, 1000);
  load.load = LoadState::kOpen;
  drive.Step(Ms{1}, config, Controlled(1000), load);
  EXPECT_TRUE(drive.Output().on);
  EXPECT_EQ(drive.Output().current_mA, 0);
  EXPECT_EQ(drive.Output().desired_mA, 1000);

  OutputDrive digital;
  DriveConfig on_off;
  on_off.type = OutputType::kDigital;
  on_off.fv_max = 1;
  LoadModel heavy;
  heavy.resistance_ohm = 4;  // 24 V / 4 ohm = 6 A > 4 A
  DriveCommand command = Controlled(1);
  command.control.signal = Ranged(1, 0, 1);
  digital.Step(Ms{1}, on_off, command, heavy);
  EXPECT_TRUE(digital.Output().tripped);
}

// Table 8: voltage (Vps switched to the mean), PWM (duty at 2380h), disabled.
TEST(OutputDriveTest, VoltagePwmAndDisabledTypes) {
  OutputDrive drive;
  DriveConfig config;
  config.type = OutputType::kVoltage;
  config.fv_digits = 1;
  config.fv_max = 600;
  config.ramp_up_ms = config.ramp_down_ms = 0;
  LoadModel load;
  DriveCommand command;
  command.control.used = true;
  command.control.signal = Ranged(200, 0, 600);  // a third: 20.0 V
  drive.Step(Ms{1}, config, command, load);
  EXPECT_DOUBLE_EQ(drive.Output().target_fv, 200.0);
  EXPECT_DOUBLE_EQ(drive.Output().voltage_V, 20.0);
  EXPECT_DOUBLE_EQ(drive.Output().current_mA, 2500.0);
  EXPECT_EQ(drive.Output().frequency_Hz, 25000);
  config.type = OutputType::kPwm;
  config.fv_max = 1000;
  load.pwm_frequency_Hz = 2000;
  command.control.signal = Ranged(250, 0, 1000);
  drive.Step(Ms{1}, config, command, load);
  EXPECT_DOUBLE_EQ(drive.Output().duty_pct, 25.0);
  EXPECT_DOUBLE_EQ(drive.Output().voltage_V, 6.0);
  EXPECT_EQ(drive.Output().frequency_Hz, 2000);
  config.type = OutputType::kDisabled;
  drive.Step(Ms{1}, config, command, load);
  EXPECT_FALSE(drive.Output().on);
  EXPECT_EQ(drive.Output().target_fv, 0);
}

}  // namespace
}  // namespace canfleet::devices::encoder::test
