// Simulated I/O (design decision 5): typed, range-checked inputs with clear errors, outputs only
// the device sets, and change notification.
#include "node/devices/simulated_io.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace canfleet::devices {
namespace {

class SimulatedIoTest : public ::testing::Test {
 protected:
  SimulatedIoTest() {
    voltage = &io.AddInput(NumberSpec("IN1.voltage_mV", "mV", 0, 36000, 2500, "voltage"));
    level = &io.AddInput(EnumSpec("IN3.level", {"open", "high", "low"}, "open", "pin"));
    enable = &io.AddInput(BoolSpec("EN.on", false, "enable"));
    current = &io.AddOutput(NumberSpec("OUT1.current_mA", "mA", 0, 0, 0, "current"));
  }
  SimulatedIo io;
  IoSignal* voltage;
  IoSignal* level;
  IoSignal* enable;
  IoSignal* current;
};

TEST_F(SimulatedIoTest, InputsStartAtTheirDeclaredDefaults) {
  EXPECT_EQ(io.Number("IN1.voltage_mV"), 2500);
  EXPECT_EQ(io.Enum("IN3.level"), "open");
  EXPECT_FALSE(io.Bool("EN.on"));
  EXPECT_EQ(voltage->ToString(), "2500 mV");
}

TEST_F(SimulatedIoTest, SetsTypedValuesWithinRange) {
  EXPECT_TRUE(io.SetNumber("IN1.voltage_mV", 4800.5).ok());
  EXPECT_DOUBLE_EQ(voltage->Number(), 4800.5);
  EXPECT_TRUE(io.SetEnum("IN3.level", "low").ok());
  EXPECT_TRUE(level->Is("low"));
  EXPECT_TRUE(io.SetBool("EN.on", true).ok());
  EXPECT_TRUE(enable->Bool());
}

TEST_F(SimulatedIoTest, RefusesWithAClearMessageAndKeepsTheValue) {
  EXPECT_EQ(io.SetNumber("IN1.voltage_mV", 40000).error, "IN1.voltage_mV: 40000 is out of range 0..36000 mV");
  EXPECT_EQ(io.SetNumber("IN1.voltage_mV", -1).error, "IN1.voltage_mV: -1 is out of range 0..36000 mV");
  EXPECT_EQ(io.SetEnum("IN3.level", "broken").error, "IN3.level: \"broken\" is not one of open|high|low");
  EXPECT_EQ(io.SetBool("IN1.voltage_mV", true).error, "IN1.voltage_mV: expected a number");
  EXPECT_EQ(io.SetNumber("IN3.level", 1).error, "IN3.level: expected open|high|low");
  const IoStatus unknown = io.SetNumber("IN9.voltage_mV", 1);
  EXPECT_EQ(unknown.error, "no signal IN9.voltage_mV; nearest: IN1.voltage_mV");
  EXPECT_TRUE(unknown.unknown);
  EXPECT_EQ(unknown.nearest, std::vector<std::string>{"IN1.voltage_mV"});
  EXPECT_EQ(io.SetNumber("nothing.like_it", 1).error, "no signal nothing.like_it");
  EXPECT_EQ(io.SetNumber("OUT1.current_mA", 5).error,
            "OUT1.current_mA is an output: the device sets it, a test only reads it");
  EXPECT_EQ(voltage->Number(), 2500);
  EXPECT_EQ(level->Enum(), "open");
}

TEST_F(SimulatedIoTest, ParsesTextForEachKind) {
  EXPECT_TRUE(io.SetText("IN1.voltage_mV", "1234").ok());
  EXPECT_EQ(voltage->Number(), 1234);
  EXPECT_TRUE(io.SetText("EN.on", "ON").ok());
  EXPECT_TRUE(enable->Bool());
  EXPECT_TRUE(io.SetText("IN3.level", "high").ok());
  EXPECT_EQ(io.SetText("IN1.voltage_mV", "12x").error, "IN1.voltage_mV: \"12x\" is not a number");
  EXPECT_EQ(io.SetText("EN.on", "maybe").error, "EN.on: \"maybe\" is not true/false/on/off/1/0");
}

TEST_F(SimulatedIoTest, ListenersHearChangesOfInputsAndOutputsOnly) {
  std::vector<std::string> heard;
  auto handle = io.Subscribe([&](const IoSignal& s) { heard.push_back(s.name() + "=" + s.ToString()); });
  ASSERT_TRUE(io.SetNumber("IN1.voltage_mV", 2500).ok());  // unchanged: silent
  ASSERT_TRUE(io.SetNumber("IN1.voltage_mV", 3000).ok());
  io.Publish(*current, 750.0);
  io.Publish(*current, 750.0);                               // unchanged: silent
  ASSERT_FALSE(io.SetNumber("IN1.voltage_mV", 99999).ok());  // refused: silent
  io.Unsubscribe(handle);
  ASSERT_TRUE(io.SetNumber("IN1.voltage_mV", 100).ok());
  EXPECT_EQ(heard, (std::vector<std::string>{"IN1.voltage_mV=3000 mV", "OUT1.current_mA=750 mA"}));
}

TEST_F(SimulatedIoTest, ResetInputsRestoresDefaults) {
  ASSERT_TRUE(io.SetNumber("IN1.voltage_mV", 100).ok());
  io.ResetInputs();
  EXPECT_EQ(voltage->Number(), 2500);
}

TEST(SimulatedIoDeclaration, RejectsDuplicatesAndDefaultsOutsideTheRange) {
  SimulatedIo io;
  io.AddInput(NumberSpec("A.x_mV", "mV", 0, 10, 5, ""));
  EXPECT_THROW(io.AddInput(NumberSpec("A.x_mV", "mV", 0, 10, 5, "")), std::logic_error);
  EXPECT_THROW(io.AddInput(NumberSpec("A.y_mV", "mV", 0, 10, 11, "")), std::logic_error);
  EXPECT_THROW(io.AddInput(EnumSpec("A.z", {"a"}, "b", "")), std::logic_error);
  EXPECT_THROW(io.AddInput(BoolSpec("nodot", false, "")), std::logic_error);
}

// node/devices/README.md "Signals", the unit rule: a number's unit is one of SignalUnits() and ends
// its name; telemetry's IoValue.name is a string<31>.
TEST(SimulatedIoDeclaration, EnforcesTheUnitRuleAndTheNameLength) {
  SimulatedIo io;
  EXPECT_NO_THROW(io.AddInput(NumberSpec("IN1.duty_pct", "pct", 0, 100, 50, "")));
  EXPECT_THROW(io.AddInput(NumberSpec("IN2.duty_pct", "%", 0, 100, 50, "")), std::logic_error);
  EXPECT_THROW(io.AddInput(NumberSpec("VPS.voltage_V", "V", 0, 70, 24, "")), std::logic_error);
  EXPECT_THROW(io.AddInput(NumberSpec("IN3.voltage_mA", "mV", 0, 1, 0, "")), std::logic_error);
  EXPECT_NO_THROW(io.AddInput(NumberSpec("ENC.speed_counts_s", "counts/s", 0, 1, 0, "")));
  EXPECT_THROW(io.AddInput(BoolSpec("CHANNEL.a_name_longer_than_thirty", false, "")), std::logic_error);
}

// The old names (the alias tables): a set and a read through one convert a changed unit and say
// which name to use; a wrong value names both.
TEST_F(SimulatedIoTest, OldNamesWorkWithADeprecationNotice) {
  io.AddAlias({"AIN1.voltage_V", "IN1.voltage_mV", 0.001});
  io.AddAlias({"DIN3.level", "IN3.level"});
  const IoStatus set = io.SetText("AIN1.voltage_V", "3.5");
  ASSERT_TRUE(set.ok()) << set.error;
  EXPECT_EQ(voltage->Number(), 3500);
  EXPECT_EQ(set.notice, "AIN1.voltage_V is deprecated: use IN1.voltage_mV (1 V = 1000 mV)");
  const IoName read = io.Resolve("AIN1.voltage_V");
  EXPECT_EQ(read.signal, voltage);
  EXPECT_EQ(read.ValueText(), "3.5");
  EXPECT_EQ(read.Unit(), "V");
  EXPECT_EQ(io.SetEnum("DIN3.level", "high").notice, "DIN3.level is deprecated: use IN3.level");
  EXPECT_TRUE(level->Is("high"));
  EXPECT_EQ(io.SetNumber("AIN1.voltage_V", 40).error,
            "AIN1.voltage_V (now IN1.voltage_mV): IN1.voltage_mV: 40000 is out of range 0..36000 mV");
  EXPECT_EQ(voltage->Number(), 3500);
  EXPECT_THROW(io.AddAlias({"X.y", "NO.such"}), std::logic_error);
  EXPECT_THROW(io.AddAlias({"IN3.level", "IN1.voltage_mV"}), std::logic_error);
}

// One pin, one channel: a set the device's configuration does not read is done, with a notice.
TEST_F(SimulatedIoTest, TheIgnoredHookTurnsIntoANotice) {
  io.SetIgnoredHook([this](const IoSignal& s) {
    return &s == level ? IgnoredNotice(s, "IN3's configuration (6112h sub 3 = 1)", "it reads IN3.voltage_mV")
                       : std::string();
  });
  const IoStatus set = io.SetEnum("IN3.level", "high");
  EXPECT_TRUE(set.ok());
  EXPECT_TRUE(level->Is("high"));
  EXPECT_EQ(set.notice,
            "IN3.level is set, but IN3's configuration (6112h sub 3 = 1) does not read it (it reads "
            "IN3.voltage_mV)");
  EXPECT_EQ(io.SetNumber("IN1.voltage_mV", 1).notice, "");
}

}  // namespace
}  // namespace canfleet::devices
