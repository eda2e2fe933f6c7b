// The Quad's digital output block (AX020506 §2.5, §3.4, §4.2): CAN control through 6200h/RPDO2,
// any input as control, polarity, latched response, POUTs as digital outputs, NMT states.
#include "tests/unit/devices/quad_fixture.hpp"

namespace canfleet::devices::test {
namespace {

class QuadDoTest : public QuadTest {
 protected:
  bool Dout() { return io().Bool("OUT5.on"); }
};

// §3.1.1 RPDO2 (6200h.1) → §3.4.5: bit 4 switches DOUT; 300Ch reports it and TPDO3 carries it.
TEST_F(QuadDoTest, Rpdo2SwitchesDoutAndTpdo3ReportsIt) {
  Start();
  SilenceTpdoTimers();
  Send("305#10");
  EXPECT_FALSE(Dout());
  Advance(1ms);
  EXPECT_TRUE(Dout());
  EXPECT_EQ(Read(0x300C, 1), 0x10);
  EXPECT_EQ(Frames(), std::vector<std::string>{"385#0010"});
  Send("305#00");
  Advance(1ms);
  EXPECT_FALSE(Dout());
}

// §4.2: under CAN control an output is off outside operational; the written state returns with
// operational. SDO writes to 6200h are refused in pre-operational.
TEST_F(QuadDoTest, CanControlledOutputsAreOffOutsideOperational) {
  EXPECT_EQ(TryWrite(0x6200, 1, 0x10, 1), SdoAborted(0x6200, 1, 0x08000022));
  Start();
  Write(0x6200, 1, 0x10, 1);
  Advance(1ms);
  EXPECT_TRUE(Dout());
  Send("000#8005");  // enter pre-operational
  Advance(1ms);
  EXPECT_FALSE(Dout());
  Start();
  EXPECT_TRUE(Dout());
  Send("000#0205");  // stop
  Advance(1ms);
  EXPECT_FALSE(Dout());
}

// §3.4.1 note 1 and §4.2: an input as control source (ON/OFF with 2001h/2002h even in normal
// mode) drives the output in pre-operational too; stopped turns it off.
TEST_F(QuadDoTest, AnInputControlsTheOutputWithoutTheBus) {
  Write(0x3001, 5, 1, 1);  // DOUT ← AIN1
  SetNumber("IN1.voltage_mV", 4000);
  Advance(11ms);
  EXPECT_TRUE(Dout());
  EXPECT_EQ(Read(0x6000, 1), 0);  // AIN1 stays a normal analog input
  SetNumber("IN1.voltage_mV", 1000);
  Advance(10ms);
  EXPECT_FALSE(Dout());
  SetNumber("IN1.voltage_mV", 4000);
  Send("000#0205");
  Advance(10ms);
  EXPECT_FALSE(Dout());
}

// §3.4.1 note 2: control inputs 11-16 read OFF unless that input is in digital mode.
TEST_F(QuadDoTest, DigitalInputControlNeedsDigitalMode) {
  Write(0x3001, 5, 12, 1);  // DOUT ← DIN2
  SetEnum("IN2.level", "high");
  Advance(11ms);
  EXPECT_FALSE(Dout());
  Write(0x6112, 2, 10, 1);
  Advance(10ms);
  EXPECT_TRUE(Dout());
}

// §3.4.5: with an on-board control input, writes to 6200h have no effect.
TEST_F(QuadDoTest, WritesTo6200hAreIgnoredUnderInputControl) {
  Start();
  Write(0x3001, 5, 11, 1);
  Write(0x6200, 1, 0x10, 1);
  Advance(10ms);
  EXPECT_FALSE(Dout());
}

// §3.4.6: 6202h bit set → the output is on while the control is off.
TEST_F(QuadDoTest, PolarityInvertsTheOutput) {
  Start();
  Write(0x6202, 1, 0x10, 1);
  Advance(1ms);
  EXPECT_TRUE(Dout());
  Write(0x6200, 1, 0x10, 1);
  Advance(1ms);
  EXPECT_FALSE(Dout());
}

// §3.4.2: latched: each new ON of the control toggles the output; 6202h is ignored.
TEST_F(QuadDoTest, LatchedResponseTogglesOnEachNewOn) {
  Write(0x3002, 1, 0x10, 1);
  Write(0x6202, 1, 0x10, 1);
  Write(0x3001, 5, 11, 1);
  Write(0x6112, 1, 10, 1);
  Advance(11ms);
  EXPECT_FALSE(Dout());
  SetEnum("IN1.level", "high");
  Advance(10ms);
  EXPECT_TRUE(Dout());
  SetEnum("IN1.level", "open");
  Advance(10ms);
  EXPECT_TRUE(Dout());
  SetEnum("IN1.level", "high");
  Advance(10ms);
  EXPECT_FALSE(Dout());
}

// §3.5.15: 6310h = 1000 makes POUT1 a digital output of the DO block (6200h bit 0, 300Ch bit 0);
// the load draws its current (30C0h).
TEST_F(QuadDoTest, PoutConfiguredAsDigitalIsADigitalOutput) {
  Start();
  SilenceTpdoTimers();
  Write(0x6310, 1, 1000, 2);
  SetNumber("OUT1.load_current_mA", 800);
  Send("305#01");
  Advance(1ms);
  EXPECT_TRUE(io().Bool("OUT1.on"));
  EXPECT_EQ(io().Number("OUT1.current_mA"), 800);
  EXPECT_EQ(Read(0x30C0, 1), 800);
  EXPECT_EQ(Frames(), std::vector<std::string>{"385#0001"});
  // In current mode the 6200h bit is ignored and 300Ch reads 0 for it.
  Write(0x6310, 1, 20, 2);
  Advance(1ms);
  EXPECT_FALSE(io().Bool("OUT1.on"));
  EXPECT_EQ(Read(0x300C, 1), 0);
}

// §3.4.1, §3.5.15: values not listed → SDO abort, previous value kept.
TEST_F(QuadDoTest, InvalidControlInputOrOutputTypeIsRefused) {
  EXPECT_EQ(TryWrite(0x3001, 5, 7, 1), SdoAborted(0x3001, 5, 0x06090030));
  EXPECT_EQ(TryWrite(0x3001, 1, 17, 1), SdoAborted(0x3001, 1, 0x06090030));
  EXPECT_EQ(TryWrite(0x6310, 2, 40, 2), SdoAborted(0x6310, 2, 0x06090030));
  EXPECT_EQ(Read(0x3001, 5), 0);
  EXPECT_EQ(Read(0x6310, 2), 20);
}

}  // namespace
}  // namespace canfleet::devices::test
