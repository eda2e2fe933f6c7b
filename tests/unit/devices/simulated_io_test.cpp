// Simulated I/O (design decision 5): typed, range-checked inputs with clear errors, outputs only
// the device sets, and change notification.
#include "node/devices/simulated_io.hpp"

#include <gtest/gtest.h>

namespace canfleet::devices {
namespace {

class SimulatedIoTest : public ::testing::Test {
 protected:
  SimulatedIoTest() {
    voltage = &io.AddInput(NumberSpec("AIN1.voltage_mV", "mV", 0, 36000, 2500, "voltage"));
    level = &io.AddInput(EnumSpec("DIN3.level", {"open", "high", "low"}, "open", "pin"));
    enable = &io.AddInput(BoolSpec("EN.on", false, "enable"));
    current = &io.AddOutput(NumberSpec("POUT1.current_mA", "mA", 0, 0, 0, "current"));
  }
  SimulatedIo io;
  IoSignal* voltage;
  IoSignal* level;
  IoSignal* enable;
  IoSignal* current;
};

TEST_F(SimulatedIoTest, InputsStartAtTheirDeclaredDefaults) {
  EXPECT_EQ(io.Number("AIN1.voltage_mV"), 2500);
  EXPECT_EQ(io.Enum("DIN3.level"), "open");
  EXPECT_FALSE(io.Bool("EN.on"));
  EXPECT_EQ(voltage->ToString(), "2500 mV");
}

TEST_F(SimulatedIoTest, SetsTypedValuesWithinRange) {
  EXPECT_TRUE(io.SetNumber("AIN1.voltage_mV", 4800.5).ok());
  EXPECT_DOUBLE_EQ(voltage->Number(), 4800.5);
  EXPECT_TRUE(io.SetEnum("DIN3.level", "low").ok());
  EXPECT_TRUE(level->Is("low"));
  EXPECT_TRUE(io.SetBool("EN.on", true).ok());
  EXPECT_TRUE(enable->Bool());
}

TEST_F(SimulatedIoTest, RefusesWithAClearMessageAndKeepsTheValue) {
  EXPECT_EQ(io.SetNumber("AIN1.voltage_mV", 40000).error,
            "AIN1.voltage_mV: 40000 is out of range 0..36000 mV");
  EXPECT_EQ(io.SetNumber("AIN1.voltage_mV", -1).error, "AIN1.voltage_mV: -1 is out of range 0..36000 mV");
  EXPECT_EQ(io.SetEnum("DIN3.level", "broken").error, "DIN3.level: \"broken\" is not one of open|high|low");
  EXPECT_EQ(io.SetBool("AIN1.voltage_mV", true).error, "AIN1.voltage_mV: expected a number");
  EXPECT_EQ(io.SetNumber("DIN3.level", 1).error, "DIN3.level: expected open|high|low");
  EXPECT_EQ(io.SetNumber("AIN9.voltage_mV", 1).error, "unknown signal \"AIN9.voltage_mV\"");
  EXPECT_EQ(io.SetNumber("POUT1.current_mA", 5).error,
            "POUT1.current_mA is an output: the device sets it, a test only reads it");
  EXPECT_EQ(voltage->Number(), 2500);
  EXPECT_EQ(level->Enum(), "open");
}

TEST_F(SimulatedIoTest, ParsesTextForEachKind) {
  EXPECT_TRUE(io.SetText("AIN1.voltage_mV", "1234").ok());
  EXPECT_EQ(voltage->Number(), 1234);
  EXPECT_TRUE(io.SetText("EN.on", "ON").ok());
  EXPECT_TRUE(enable->Bool());
  EXPECT_TRUE(io.SetText("DIN3.level", "high").ok());
  EXPECT_EQ(io.SetText("AIN1.voltage_mV", "12x").error, "AIN1.voltage_mV: \"12x\" is not a number");
  EXPECT_EQ(io.SetText("EN.on", "maybe").error, "EN.on: \"maybe\" is not true/false/on/off/1/0");
}

TEST_F(SimulatedIoTest, ListenersHearChangesOfInputsAndOutputsOnly) {
  std::vector<std::string> heard;
  auto handle = io.Subscribe([&](const IoSignal& s) { heard.push_back(s.name() + "=" + s.ToString()); });
  ASSERT_TRUE(io.SetNumber("AIN1.voltage_mV", 2500).ok());  // unchanged: silent
  ASSERT_TRUE(io.SetNumber("AIN1.voltage_mV", 3000).ok());
  io.Publish(*current, 750.0);
  io.Publish(*current, 750.0);                                // unchanged: silent
  ASSERT_FALSE(io.SetNumber("AIN1.voltage_mV", 99999).ok());  // refused: silent
  io.Unsubscribe(handle);
  ASSERT_TRUE(io.SetNumber("AIN1.voltage_mV", 100).ok());
  EXPECT_EQ(heard, (std::vector<std::string>{"AIN1.voltage_mV=3000 mV", "POUT1.current_mA=750 mA"}));
}

TEST_F(SimulatedIoTest, ResetInputsRestoresDefaults) {
  ASSERT_TRUE(io.SetNumber("AIN1.voltage_mV", 100).ok());
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

}  // namespace
}  // namespace canfleet::devices
