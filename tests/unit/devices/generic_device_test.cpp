// The generic node (design decision 4): `--eds FILE` without --device runs a CiA 301 slave whose
// dictionary is the EDS's, here a third-party-style DS-401 file written by hand
// (data/acme-dio8-ai2.eds). The registry chooses between variants and the generic node.
#include <gtest/gtest.h>

#include <optional>

#include "bus/loopback_bus.hpp"
#include "node/canopen/eds/eds.hpp"
#include "node/canopen/sdo/sdo_client.hpp"
#include "node/devices/device_node.hpp"
#include "node/devices/generic_device.hpp"
#include "node/devices/registry.hpp"
#include "tests/support/bus_probe.hpp"

namespace canfleet::devices {
namespace {

using namespace std::chrono_literals;

const std::filesystem::path kAcmeEds =
    std::filesystem::path(CANFLEET_DEVICES_TEST_DATA) / "acme-dio8-ai2.eds";

class GenericNodeTest : public ::testing::Test {
 protected:
  GenericNodeTest()
      : node_port_(bus_.Attach("node")),
        master_(bus_, "master"),
        node_(MakeDevice({"", kAcmeEds}), scheduler_, {&node_port_},
              NodeSettings{{PortSettings{10, 4}}, {}, {}, {}}) {
    node_.Start();
  }
  SimulatedScheduler scheduler_;
  LoopbackBus bus_;
  LoopbackPort& node_port_;
  canfleet::test::BusProbe master_;
  DeviceNode node_;
};

// CiA 301 §7.2.8.3.3 boot-up, §7.2.4 SDO on 600h/580h + node-ID, the EDS's values.
TEST_F(GenericNodeTest, BootsAndServesTheEdsDictionary) {
  EXPECT_EQ(node_.device().Name(), "generic");
  EXPECT_TRUE(node_.io().Signals().empty());
  EXPECT_EQ(master_.Take(), std::vector<std::string>{"70A#00"});
  master_.Send("60A#4000100000000000");
  EXPECT_EQ(master_.Next(), "58A#4300100091010F00");
  master_.Send("60A#4018100100000000");
  EXPECT_EQ(master_.Next(), "58A#4318100101E0AC00");
  master_.Send("60A#4014100000000000");  // $NODEID+0x80
  EXPECT_EQ(master_.Next(), "58A#431410008A000000");
  master_.Send("60A#2B00200000010000");  // 2000h HighLimit 250
  EXPECT_EQ(master_.Next(), "58A#8000200031000906");
}

// A string object travels by segmented upload (CiA 301 §7.2.4.3.5); the project's client reads it.
TEST_F(GenericNodeTest, ReadsTheDeviceNameBySegmentedUpload) {
  LoopbackPort& client_port = bus_.Attach("client");
  canopen::SdoClient client(client_port, scheduler_);
  client_port.OnReceive([&](const CanFrame& f, BusTime) { client.OnFrame(f); });
  std::optional<std::string> name;
  ASSERT_TRUE(client.Upload(10, 0x1008, 0, canopen::SdoMode::kAuto,
                            [&](canopen::SdoAbort abort, canopen::Bytes data) {
                              if (abort == canopen::SdoAbort::kNone)
                                name = std::string(data.begin(), data.end());
                            }));
  scheduler_.Advance(1ms);
  EXPECT_EQ(name, "ACME DIO8-AI2");
}

// CiA 301 §7.2.2: the EDS's default PDOs run in operational: RPDO1 writes 6200h.1, RPDO2 the
// CompactSubObj array 6411h; TPDO1 sends 6000h.1 once given an event timer.
TEST_F(GenericNodeTest, DefaultPdosOfTheEdsRunInOperational) {
  master_.Send("000#010A");
  master_.Send("20A#A5");
  master_.Send("30A#E803F4FF");
  master_.Clear();
  master_.Send("60A#4000620100000000");
  EXPECT_EQ(master_.Next(), "58A#4F006201A5000000");
  master_.Send("60A#4011640200000000");
  EXPECT_EQ(master_.Next(), "58A#4B116402F4FF0000");
  master_.Send("60A#2B00180564000000");  // 1800h.5 = 100 ms
  EXPECT_EQ(master_.Next(), "58A#6000180500000000");
  scheduler_.Advance(100ms);
  EXPECT_EQ(master_.Take(), std::vector<std::string>{"18A#00"});
  master_.Send("60A#2B17100032000000");  // heartbeat 50 ms
  master_.Clear();
  scheduler_.Advance(50ms);
  EXPECT_EQ(master_.Take(), std::vector<std::string>{"70A#05"});
}

TEST(DeviceRegistryTest, ListsTheQuadAndExplainsBadSelections) {
  EXPECT_NE(FindDevice("quad-controller"), nullptr);
  EXPECT_EQ(FindDevice("quad"), nullptr);
  const std::string list = ListDevices();
  // One line per variant, the columns aligned: name, ports, factory node-ID and bit rate, summary.
  const auto line_start = list.find("quad-controller ");
  ASSERT_NE(line_start, std::string::npos) << list;
  const std::string line = list.substr(line_start, list.find('\n', line_start) - line_start);
  EXPECT_NE(line.find(" 1 port   id 127 @ 125 kbit/s   Axiomatic CANopen Quad Controller AX020506"),
            std::string::npos)
      << line;
  try {
    MakeDevice({"toaster", {}});
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("unknown device \"toaster\" (known: quad-controller, ", 0), 0u)
        << e.what();
  }
  EXPECT_THROW(MakeDevice({}), std::invalid_argument);
  EXPECT_EQ(MakeDevice({"quad-controller", {}})->Name(), "quad-controller");
}

// An EDS that lacks what a variant's blocks need stops the node at build time, naming the object.
TEST(DeviceRegistryTest, AVariantWithAForeignEdsFailsAtBuildTime) {
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& port = bus.Attach("node");
  try {
    DeviceNode node(MakeDevice({"quad-controller", kAcmeEds}), scheduler, {&port}, {});
    ADD_FAILURE();
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing from the dictionary"), std::string::npos) << e.what();
  }
}

// An unreadable EDS is an edge: EdsError names the file.
TEST(DeviceRegistryTest, AMissingEdsFileIsReported) {
  SimulatedScheduler scheduler;
  LoopbackBus bus;
  LoopbackPort& port = bus.Attach("node");
  EXPECT_THROW(DeviceNode(MakeDevice({"", "/nonexistent/x.eds"}), scheduler, {&port}, {}), canopen::EdsError);
}

}  // namespace
}  // namespace canfleet::devices

namespace canfleet::devices {
namespace {

// The catalog entry is the one place for a variant's static facts: the signals and the dictionary
// the topology loader checks against come from it without creating the device, and a device made
// from it has the entry's port count.
TEST(DeviceCatalogTest, AnEntryGivesSignalsDictionaryAndPortsWithoutADevice) {
  const DeviceInfo* quad = FindDevice("quad-controller");
  ASSERT_NE(quad, nullptr);
  const auto signals = SignalsOf(*quad);
  ASSERT_NE(signals->Find("IN1.voltage_mV"), nullptr);
  EXPECT_EQ(signals->Find("OUT1.current_mA")->direction(), IoDirection::kOutput);
  const canopen::ObjectDictionary od = VariantDictionary(*quad);
  EXPECT_EQ(od.GetUnsigned(0x1018, 2), 0xAA020502u);  // AX020506 §3.1, 1018h sub 2
  EXPECT_EQ(MakeDevice({"quad-controller", {}})->PortCount(), quad->ports);
  EXPECT_EQ(quad->eds().Text().substr(0, 10), "[FileInfo]");
}

// CiA 305 §5.5 table 0: the bit timing index of each bit rate; 100 kbit/s (index 5) is reserved.
TEST(DeviceCatalogTest, BitTimingIndexesFollowCia305Table0) {
  EXPECT_EQ(BitTimingIndexOf(1000), 0);
  EXPECT_EQ(BitTimingIndexOf(125), 4);
  EXPECT_EQ(BitTimingIndexOf(10), 8);
  EXPECT_EQ(BitTimingIndexOf(100), std::nullopt);
  EXPECT_EQ(BitTimingIndexOf(333), std::nullopt);
}

}  // namespace
}  // namespace canfleet::devices
