// One signal vocabulary for every product (node/devices/README.md "Signals"): the naming rule
// (IN<n>/OUT<n> as the manual numbers the channels in its per-channel objects, named channels for
// the rest), the unit rule, the alias tables of the old names, and the notice when a set quantity
// is not what the pin's configuration reads (the family's 6112h/6110h rule).
#include <gtest/gtest.h>

#include <regex>
#include <set>
#include <string>

#include "node/devices/registry.hpp"
#include "tests/unit/devices/quad_fixture.hpp"

namespace canfleet::devices::test {
namespace {

// The README's naming rule: a channel is IN<n>, OUT<n>, TC<n> or one of the named channels.
TEST(SignalVocabulary, EveryProductFollowsTheNamingRule) {
  const std::regex channel(R"((IN|OUT|TC)[1-9][0-9]?|VPS|TEMP|CJ|ENC|VIN|VOUT|IIN|IOUT|ENABLE|LOAD|PS)");
  for (const DeviceInfo& info : Devices()) {
    const auto io = SignalsOf(info);
    ASSERT_FALSE(io->Signals().empty()) << info.name;
    for (const auto& signal : io->Signals()) {
      const std::string& name = signal->name();
      EXPECT_LE(name.size(), kMaxSignalNameLength) << name;
      EXPECT_TRUE(std::regex_match(name.substr(0, name.find('.')), channel)) << info.name << ": " << name;
      // The manuals' own names are aliases now, never signals.
      EXPECT_FALSE(std::regex_search(name, std::regex(R"(^(AIN|FIN|DIN|POUT|DOUT|UI|DI|DO)\d*\.)"))) << name;
    }
    for (const auto& alias : io->Aliases()) {
      const IoName resolved = io->Resolve(alias->old_name);
      ASSERT_NE(resolved.signal, nullptr) << alias->old_name;
      EXPECT_EQ(resolved.signal->name(), alias->new_name);
      EXPECT_NE(resolved.notice.find("deprecated: use " + alias->new_name), std::string::npos);
    }
  }
}

// AX020506 §1.1/§3.3: AIN1-4 are sub 1-4, FIN1-2 sub 5-6 of every per-input object, DIN1-6 the
// same pins; POUT1-4 are outputs 1-4, DOUT output 5 (bit 4). The old names land on those.
TEST(SignalVocabulary, QuadChannelsAreNumberedAsItsObjectsNumberThem) {
  const auto io = SignalsOf(*FindDevice("quad-controller"));
  const auto target = [&](const char* old) { return io->Resolve(old).signal->name(); };
  EXPECT_EQ(target("AIN2.voltage_mV"), "IN2.voltage_mV");
  EXPECT_EQ(target("DIN2.level"), "IN2.level");
  EXPECT_EQ(target("FIN2.frequency_Hz"), "IN6.frequency_Hz");
  EXPECT_EQ(target("DIN6.level"), "IN6.level");
  EXPECT_EQ(target("POUT3.current_mA"), "OUT3.current_mA");
  EXPECT_EQ(target("DOUT.on"), "OUT5.on");
  const auto valve = SignalsOf(*FindDevice("valve-12in12out"));  // UMAX020411A §2.1
  EXPECT_EQ(valve->Resolve("UI1.voltage_mV").signal->name(), "IN1.voltage_mV");
  EXPECT_EQ(valve->Resolve("DI1.level").signal->name(), "IN8.level");
  EXPECT_EQ(valve->Resolve("DO4.on").signal->name(), "OUT12.on");
}

class QuadSignalTest : public QuadTest {};

// §3.3.13: 51 = 4-20 mA, the field value (7100h) in uA; the signal counts mA like the family's
// other current objects, and the old AINn.current_uA still sets it in uA.
TEST_F(QuadSignalTest, CurrentInputsAreInMilliamperes) {
  Write(0x6110, 1, 51, 2);
  SetNumber("IN1.current_mA", 12.345);
  Advance(20ms);
  EXPECT_EQ(Read(0x7100, 1), 12345);
  const IoStatus old = io().SetText("AIN1.current_uA", "8000");
  ASSERT_TRUE(old.ok()) << old.error;
  EXPECT_EQ(old.notice, "AIN1.current_uA is deprecated: use IN1.current_mA (1000 uA = 1 mA)");
  EXPECT_EQ(io().Number("IN1.current_mA"), 8);
  Advance(20ms);
  EXPECT_EQ(Read(0x7100, 1), 8000);
}

// §3.3.14: 6112h = 1 measures per 6110h (40: 0-5 V), 10 reads the pin's level. IN2.level at the
// defaults is accepted and the device says it does not read it; once IN2 is digital, the voltage
// is the one it does not read.
TEST_F(QuadSignalTest, ASetTheConfigurationIgnoresSaysSo) {
  const IoStatus level = io().SetEnum("IN2.level", "high");
  ASSERT_TRUE(level.ok());
  EXPECT_EQ(
      level.notice,
      "IN2.level is set, but IN2's configuration (6112h sub 2 = 1, 6110h sub 2 = 40) does not read it (it "
      "reads IN2.voltage_mV)");
  EXPECT_EQ(io().SetNumber("IN2.voltage_mV", 1000).notice, "");
  Write(0x6112, 2, 10, 1);
  EXPECT_EQ(io().SetEnum("IN2.level", "low").notice, "");
  EXPECT_NE(io().SetNumber("IN2.voltage_mV", 1200).notice.find("(it reads IN2.level)"), std::string::npos);
  // §3.5.15: the load's own current applies to a digital output (6310h = 1000) only.
  EXPECT_NE(io().SetNumber("OUT1.load_current_mA", 500).notice.find("6310h sub 1 = 1000 reads it"),
            std::string::npos);
  Write(0x6310, 1, 1000, 2);
  EXPECT_EQ(io().SetNumber("OUT1.load_current_mA", 600).notice, "");
}

}  // namespace
}  // namespace canfleet::devices::test
