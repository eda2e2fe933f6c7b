// The AX023241 dictionary as the node serves it (encoder-dual-valve.od, C3-1.2-C3-1.4): identity,
// default PDOs with $NODEID, the corrected defaults (README.md "Fixes to the table"), and the
// factory values of the simulated I/O (no fault at factory defaults).
#include "tests/unit/encoder/encoder_fixture.hpp"

namespace canfleet::devices::encoder::test {
namespace {

class DictionaryTest : public EncoderTest {};

// C3-1.2.1, C3-1.2.9: device type 0x192, vendor 55h, product code AA023241h.
TEST_F(DictionaryTest, Identity) {
  EXPECT_EQ(Read(0x1000, 0), 0x192);
  EXPECT_EQ(Read(0x1018, 1), 0x55);
  EXPECT_EQ(Read(0x1018, 2), 0xAA023241);
  EXPECT_EQ(EncoderValveController::kName, "encoder-dual-valve");
  EXPECT_EQ(EncoderValveController::kFactoryNodeId, 127);
  EXPECT_EQ(EncoderValveController::kFactoryBitRateKbit, 125u);
}

// C3-1.2.12-1.2.27: RPDO1 and TPDO1 valid, the others invalid; COB-IDs follow the node-ID.
TEST_F(DictionaryTest, DefaultPdos) {
  EXPECT_EQ(Read(0x1400, 1), 0x40000205);
  EXPECT_EQ(Read(0x1401, 1), 0xC0000305);
  EXPECT_EQ(Read(0x1800, 1), 0x40000185);
  EXPECT_EQ(Read(0x1800, 5), 100);
  EXPECT_EQ(Read(0x1A00, 1), 0x71000110);
  EXPECT_EQ(Read(0x1A02, 1), 0x50200020);
  EXPECT_EQ(Read(0x1600, 1), 0x73000110);
}

// README.md fixes: enable and override sources default to "not used" (2350h/2360h = 0), 6340h
// accepts Table 12's three responses; 1029h defaults to "no change" (C3-1.2.11); 1003h is empty.
TEST_F(DictionaryTest, CorrectedDefaults) {
  EXPECT_EQ(Read(0x2350, 1), 0);
  EXPECT_EQ(Read(0x2360, 2), 0);
  EXPECT_EQ(Read(0x2351, 2), 2);
  EXPECT_EQ(Read(0x2340, 1), 1);
  EXPECT_EQ(Read(0x2341, 2), 2);
  Write(0x6340, 1, 2, 1);
  EXPECT_EQ(Read(0x1029, 1), 1);
  EXPECT_EQ(Read(0x1029, 6), 1);
  EXPECT_EQ(Read(0x1003, 0), 0);
  EXPECT_EQ(Read(0x6110, 1), 10002);
}

// Design decision 5 / issue 17: an idle node at factory defaults raises no fault and does not
// wake: after a minute in operational only its TPDO1 is on the bus.
TEST_F(DictionaryTest, IdleNodeAtFactoryDefaultsIsQuietAndAsleep) {
  Start();
  Advance(60000ms);
  const auto frames = Frames();
  EXPECT_EQ(frames.size(), 600u);
  for (const auto& f : frames)
    EXPECT_EQ(f, "185#00000000");
  EXPECT_EQ(Read(0x1001, 0), 0);
  EXPECT_FALSE(device().Ticking());
  EXPECT_LE(device().Evaluations(), 3u);
}

// The catalog declares the signals without a device (registry.hpp declare_signals).
TEST(EncoderSignalsTest, DeclaredWithoutADevice) {
  SimulatedIo io;
  DeclareEncoderSignals(io);
  for (const char* name : {"ENC.speed_rpm", "ENC.position_counts", "ENC.direction", "IN1.frequency_Hz",
                           "IN2.duty_pct", "IN1.level", "VPS.voltage_mV", "TEMP.temperature_C", "OUT1.load",
                           "OUT2.current_mA", "OUT1.on", "ENC.shaft_counts"})
    EXPECT_NE(io.Find(name), nullptr) << name;
}

}  // namespace
}  // namespace canfleet::devices::encoder::test
