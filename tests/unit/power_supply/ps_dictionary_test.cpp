// The dictionary and the communication side of the PS-24-24-350W-CAN (UMAX080311 §2.1-§2.4): the
// generated EDS with node-ID relative defaults, the default PDOs and what they carry, the write
// checks of the device, storage (1010h) and 5555h, and the catalog's signal declaration.
#include <unistd.h>

#include "tests/unit/power_supply/ps_fixture.hpp"

namespace canfleet::devices::test {
namespace {

class PsDictionaryTest : public PsTest {};

// §2.2.1 1000h = 284101C5h; §2.2.11 vendor 55h, product code AA080310h.
TEST_F(PsDictionaryTest, Identity) {
  EXPECT_EQ(Read(0x1000, 0), 0x284101C5);
  EXPECT_EQ(Read(0x1018, 1), 0x55);
  EXPECT_EQ(Read(0x1018, 2), 0xAA080310);
  EXPECT_EQ(Read(0x1029, 1), 0);  // §2.2.13 communication fault → pre-operational
  EXPECT_EQ(Read(0x1029, 2), 1);
}

// §2.2.14, §2.2.15: "40000000h + RPDO1 + Node ID", "C0000000h + RPDOx + Node-ID"; TPDO1-3 exist with
// 250 ms event timers, type 254; RPDOs type 255.
TEST_F(PsDictionaryTest, PdoCobIdsFollowTheNodeId) {
  EXPECT_EQ(Read(0x1400, 1), 0x4000027F);
  EXPECT_EQ(Read(0x1402, 1), 0xC000047F);
  EXPECT_EQ(Read(0x1404, 1), 0xC0000280);  // RPDO5: 201h + node-ID
  EXPECT_EQ(Read(0x1400, 2), 0xFF);
  EXPECT_EQ(Read(0x1800, 1), 0x400001FF);
  EXPECT_EQ(Read(0x1802, 1), 0x400003FF);
  EXPECT_EQ(Read(0x1803, 1), 0xC00004FF);
  EXPECT_EQ(Read(0x1800, 2), 0xFE);
  EXPECT_EQ(Read(0x1800, 5), 250);
  EXPECT_EQ(Read(0x1803, 5), 0);
}

// §2.2.15: TPDO1 6011h.1 + 6012h.1, TPDO2 6204h.1 + 6113h.1, TPDO3 6204h.2 (+ three empty entries:
// 4 bytes), every 250 ms in operational; the values come from the model.
TEST_F(PsDictionaryTest, DefaultTpdosCarryTheModel) {
  OnByCan();
  Start();
  Frames();
  Advance(250ms);
  EXPECT_EQ(Frames("1FF#"), std::vector<std::string>{"1FF#01000000F0FFFFFF"});
  Advance(250ms);
  const auto frames = Frames();
  EXPECT_NE(std::find(frames.begin(), frames.end(), "2FF#C05D0000C05D0000"), frames.end());
  EXPECT_NE(std::find(frames.begin(), frames.end(), "3FF#E8030000"), frames.end());
}

// TPDO1 (type 254) also goes out when its status words change, not only on its timer.
TEST_F(PsDictionaryTest, Tpdo1OnChangeOfTheStatusWords) {
  Start();
  Frames();
  Advance(100ms);
  Frames();
  Send("27F#FDFF");  // RPDO1: on
  Advance(1ms);
  EXPECT_EQ(Frames("1FF#"), std::vector<std::string>{"1FF#01000000F0FFFFFF"});
}

// Write checks (ps_validators.hpp): enumerations with gaps 06090030h; 2520h < 2522h (§2.4.13/14);
// 5B51h a node-ID.
TEST_F(PsDictionaryTest, DeviceWriteChecks) {
  EXPECT_EQ(TryWrite(0x6010, 1, 0xFE, 1), SdoAborted(0x6010, 1, 0x06090030));
  EXPECT_EQ(TryWrite(0x6010, 2, 0xFD, 1), SdoAborted(0x6010, 2, 0x06090030));
  EXPECT_EQ(TryWrite(0x6200, 2, 0xFE, 1), SdoAborted(0x6200, 2, 0x06090030));
  EXPECT_EQ(TryWrite(0x6200, 3, 0xFD, 1), SdoAborted(0x6200, 3, 0x06090030));
  EXPECT_EQ(TryWrite(0x6200, 2, 0x01, 1), SdoAborted(0x6200, 2, 0x06090032));  // table limit FCh
  EXPECT_EQ(TryWrite(0x2520, 1, 1000, 2), SdoAborted(0x2520, 1, 0x06090031));
  EXPECT_EQ(TryWrite(0x2522, 1, 0, 2), SdoAborted(0x2522, 1, 0x06090032));
  Write(0x2520, 1, 999, 2);
  EXPECT_EQ(TryWrite(0x5B50, 0, 5, 1), SdoAborted(0x5B50, 0, 0x06090030));
  EXPECT_EQ(TryWrite(0x5B51, 0, 0, 1), SdoAborted(0x5B51, 0, 0x06090032));
  EXPECT_EQ(TryWrite(0x5B51, 0, 128, 1), SdoAborted(0x5B51, 0, 0x06090031));
  Write(0x5B51, 0, 5, 1);
  EXPECT_EQ(TryWrite(0x6204, 1, 0, 4), SdoAborted(0x6204, 1, 0x06010002));  // measured: read-only
}

// The catalog declares the signals without a device (registry.hpp SignalsOf).
TEST(PsSignals, DeclaredWithoutADevice) {
  SimulatedIo declared;
  PowerSupply::DeclareSignals(declared);
  PowerSupply device;
  ASSERT_EQ(declared.Signals().size(), device.io().Signals().size());
  for (std::size_t i = 0; i < declared.Signals().size(); ++i)
    EXPECT_EQ(declared.Signals()[i]->name(), device.io().Signals()[i]->name());
  for (const char* name :
       {"VIN.voltage_mV", "ENABLE.level", "LOAD.resistance_ohm", "LOAD.current_mA", "LOAD.mode",
        "TEMP.temperature_C", "PS.output_on", "VOUT.voltage_mV", "IOUT.current_mA", "PS.state"})
    EXPECT_NE(declared.Find(name), nullptr) << name;
}

std::filesystem::path StateDir() {
  return std::filesystem::path(::testing::TempDir()) /
         ("canfleet-ps-" + std::to_string(::getpid()) + "-" +
          ::testing::UnitTest::GetInstance()->current_test_info()->name());
}

class PsStorageTest : public PsTest {
 protected:
  PsStorageTest() : PsTest(Prepare()) {}
  ~PsStorageTest() override { std::filesystem::remove_all(StateDir()); }
  static std::filesystem::path Prepare() {
    std::filesystem::remove_all(StateDir());
    return StateDir();
  }
};

// §2.4.17: 5555h TRUE "allows the unit to start in Operational mode"; stored with 1010h (§2.2.7).
// Commands are not stored: after a reset the output follows the pin again, 6200h.2 is FFh.
TEST_F(PsStorageTest, StartInOperationalIsStoredCommandsAreNot) {
  Write(0x5555, 0, 1, 1);
  Write(0x2302, 0, 700, 4);
  Write(0x6200, 2, 0xFD, 1);
  Write(0x1010, 1, 0x65766173, 4);
  Send("000#817F");  // reset node
  EXPECT_EQ(Frames("77F#"), std::vector<std::string>{"77F#00"});
  EXPECT_EQ(stack().State(), canopen::NmtState::kOperational);
  Advance(2ms);
  EXPECT_EQ(Read(0x2302, 0), 700);
  EXPECT_EQ(Read(0x6200, 2), 0xFF);
  EXPECT_FALSE(io().Bool("PS.output_on"));
}

}  // namespace
}  // namespace canfleet::devices::test
