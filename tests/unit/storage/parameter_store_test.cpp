// Store/restore parameters: CiA 301 v4.2 §7.5.2.13 (1010h), §7.5.2.14 (1011h) and the CiA 305
// persistent LSS configuration. A "restart" is a fresh object dictionary and a fresh
// ParameterStore on the same state directory, brought up like the stack does at reset node:
// RestoreDefaults, then ApplyStored.
#include "node/canopen/storage/parameter_store.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <fstream>
#include <memory>

#include "node/canopen/storage/atomic_file.hpp"

namespace canfleet::canopen {
namespace {

namespace fs = std::filesystem;

constexpr std::uint32_t kProductCode = 0xAA020411;

SubObject Sub(std::string name, DataType type, Access access, Bytes default_value,
              bool adds_node_id = false) {
  SubObject sub;
  sub.name = std::move(name);
  sub.type = type;
  sub.access = access;
  sub.default_value = std::move(default_value);
  sub.default_adds_node_id = adds_node_id;
  return sub;
}

void AddRecord(ObjectDictionary& od, std::uint16_t index,
               std::vector<std::pair<std::uint8_t, SubObject>> subs) {
  Object object;
  object.index = index;
  object.code = ObjectCode::kRecord;
  for (auto& [sub_index, sub] : subs)
    object.subs.emplace(sub_index, std::move(sub));
  od.Add(std::move(object));
}

/// A small device: communication objects with "$NODEID" COB-IDs, manufacturer and application
/// objects, one object above 9FFFh, and read-only ones.
void BuildDictionary(ObjectDictionary& od, std::uint32_t product_code = kProductCode) {
  od.AddVar(0x1000, "Device type", DataType::kUnsigned32, Access::kRo, EncodeLe<std::uint32_t>(0x000F0194));
  od.AddVar(0x1003, "Error history count", DataType::kUnsigned8, Access::kRw, {0});
  AddStorageObjects(od);
  od.AddVar(0x1017, "Producer heartbeat time", DataType::kUnsigned16, Access::kRw,
            EncodeLe<std::uint16_t>(0));
  AddRecord(
      od, 0x1018,
      {{0, Sub("count", DataType::kUnsigned8, Access::kRo, {2})},
       {1, Sub("Vendor-ID", DataType::kUnsigned32, Access::kRo, EncodeLe<std::uint32_t>(0x55))},
       {2, Sub("Product code", DataType::kUnsigned32, Access::kRo, EncodeLe<std::uint32_t>(product_code))}});
  AddRecord(
      od, 0x1400,
      {{0, Sub("count", DataType::kUnsigned8, Access::kRo, {2})},
       {1, Sub("COB-ID", DataType::kUnsigned32, Access::kRw, EncodeLe<std::uint32_t>(0x40000200), true)},
       {2, Sub("Type", DataType::kUnsigned8, Access::kRo, {255})}});
  AddRecord(
      od, 0x1800,
      {{0, Sub("count", DataType::kUnsigned8, Access::kRo, {5})},
       {1, Sub("COB-ID", DataType::kUnsigned32, Access::kRw, EncodeLe<std::uint32_t>(0x40000180), true)},
       {5, Sub("Event timer", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(100))}});
  AddRecord(
      od, 0x1801,
      {{0, Sub("count", DataType::kUnsigned8, Access::kRo, {1})},
       {1, Sub("COB-ID", DataType::kUnsigned32, Access::kRw, EncodeLe<std::uint32_t>(0xC0000280), true)}});
  od.AddVar(0x2000, "Mfr word", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(1000));
  od.AddVar(0x2001, "Mfr text", DataType::kVisibleString, Access::kRw, ToBytes("default"));
  od.AddVar(0x2002, "Mfr byte", DataType::kUnsigned8, Access::kRw, {7});
  od.AddVar(0x2100, "Mfr status", DataType::kUnsigned8, Access::kRo, {0});
  od.AddVar(0x6000, "App byte", DataType::kUnsigned8, Access::kRww, {1});
  auto& limited =
      od.AddVar(0x6100, "App limited", DataType::kInteger16, Access::kRw, EncodeLe<std::int16_t>(0));
  limited.low_limit = EncodeLe<std::int16_t>(-100);
  limited.high_limit = EncodeLe<std::int16_t>(2000);
  od.AddVar(0x6200, "App command", DataType::kUnsigned32, Access::kWo, EncodeLe<std::uint32_t>(0));
  od.AddVar(0xA000, "Network variable", DataType::kUnsigned8, Access::kRw, {3});
}

Bytes Save() {
  return EncodeLe<std::uint32_t>(kSaveSignature);
}
Bytes Load() {
  return EncodeLe<std::uint32_t>(kLoadSignature);
}

/// One running node: dictionary and store.
struct Device {
  ObjectDictionary od;
  std::unique_ptr<ParameterStore> store;
  LoadReport report;
};

class ParameterStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / "canfleet-storage" /
           (std::string(info->name()) + "-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Power-on (NMT reset node) of a device with `node_id`.
  std::unique_ptr<Device> Boot(std::uint8_t node_id = 5, std::uint32_t product_code = kProductCode) {
    auto device = std::make_unique<Device>();
    BuildDictionary(device->od, product_code);
    device->store = std::make_unique<ParameterStore>(device->od, dir_);
    device->od.RestoreDefaults(0x1000, 0xFFFF, node_id);
    device->report = device->store->ApplyStored(0x1000, 0xFFFF, node_id);
    return device;
  }

  fs::path File(const char* name) const { return dir_ / name; }

  static void WriteRaw(const fs::path& path, const Bytes& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  static Bytes ReadRaw(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return Bytes(std::istreambuf_iterator<char>(in), {});
  }

  /// Changes one value in every group.
  static void ChangeEverything(ObjectDictionary& od) {
    ASSERT_EQ(od.Write(0x1017, 0, EncodeLe<std::uint16_t>(250)), SdoAbort::kNone);
    ASSERT_EQ(od.Write(0x1800, 5, EncodeLe<std::uint16_t>(20)), SdoAbort::kNone);
    ASSERT_EQ(od.Write(0x2000, 0, EncodeLe<std::uint16_t>(4242)), SdoAbort::kNone);
    ASSERT_EQ(od.Write(0x2001, 0, ToBytes("changed text")), SdoAbort::kNone);
    ASSERT_EQ(od.Write(0x6000, 0, Bytes{9}), SdoAbort::kNone);
    ASSERT_EQ(od.Write(0x6100, 0, EncodeLe<std::int16_t>(-50)), SdoAbort::kNone);
    ASSERT_EQ(od.Write(0xA000, 0, Bytes{33}), SdoAbort::kNone);
  }

  static void ExpectCommChanged(const ObjectDictionary& od, bool changed) {
    EXPECT_EQ(od.GetUnsigned(0x1017, 0), changed ? 250u : 0u);
    EXPECT_EQ(od.GetUnsigned(0x1800, 5), changed ? 20u : 100u);
  }
  static void ExpectMfrChanged(const ObjectDictionary& od, bool changed) {
    EXPECT_EQ(od.GetUnsigned(0x2000, 0), changed ? 4242u : 1000u);
    EXPECT_EQ(od.Find(0x2001, 0)->value, ToBytes(changed ? "changed text" : "default"));
  }
  static void ExpectAppChanged(const ObjectDictionary& od, bool changed) {
    EXPECT_EQ(od.GetUnsigned(0x6000, 0), changed ? 9u : 1u);
    EXPECT_EQ(od.GetSigned(0x6100, 0), changed ? -50 : 0);
  }

  fs::path dir_;
};

// CiA 301 §7.5.2.13: writing "save" to 1010h sub 1 stores all parameters; after a restart they
// are back. Objects above 9FFFh and read-only objects are not stored.
TEST_F(ParameterStoreTest, SaveAllSurvivesARestart) {
  {
    auto device = Boot();
    EXPECT_TRUE(device->report.Clean());
    EXPECT_TRUE(device->report.files_applied.empty());  // nothing stored yet: not a problem
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 1, Save()), SdoAbort::kNone);
  }
  auto device = Boot();
  EXPECT_TRUE(device->report.Clean()) << device->report.ToString();
  EXPECT_EQ(device->report.files_applied.size(), 3u);
  ExpectCommChanged(device->od, true);
  ExpectMfrChanged(device->od, true);
  ExpectAppChanged(device->od, true);
  EXPECT_EQ(device->od.GetUnsigned(0xA000, 0), 3u);  // outside every group
  EXPECT_TRUE(fs::exists(File("params-comm.bin")));
  EXPECT_TRUE(fs::exists(File("params-mfr.bin")));
  EXPECT_TRUE(fs::exists(File("params-app.bin")));
  EXPECT_FALSE(fs::exists(File("params-comm.bin.tmp")));  // renamed into place
}

// CiA 301 §7.5.2.13/14: reading a sub-index gives 1 (saves on command / can restore), also
// right after a successful save or restore.
TEST_F(ParameterStoreTest, StoreAndRestoreSubIndexesReadOne) {
  auto device = Boot();
  Bytes out;
  for (std::uint16_t index : {std::uint16_t{0x1010}, std::uint16_t{0x1011}}) {
    for (std::uint8_t sub = 1; sub <= 4; ++sub) {
      ASSERT_EQ(device->od.Read(index, sub, out), SdoAbort::kNone);
      EXPECT_EQ(out, EncodeLe<std::uint32_t>(1));
    }
    ASSERT_EQ(device->od.Read(index, 0, out), SdoAbort::kNone);
    EXPECT_EQ(out, Bytes{4});
  }
  ASSERT_EQ(device->od.Write(0x1010, 2, Save()), SdoAbort::kNone);
  ASSERT_EQ(device->od.Read(0x1010, 2, out), SdoAbort::kNone);
  EXPECT_EQ(out, EncodeLe<std::uint32_t>(1));
  EXPECT_EQ(device->od.Find(0x1010, 2)->value, EncodeLe<std::uint32_t>(1));
  ASSERT_EQ(device->od.Write(0x1011, 2, Load()), SdoAbort::kNone);
  ASSERT_EQ(device->od.Read(0x1011, 2, out), SdoAbort::kNone);
  EXPECT_EQ(out, EncodeLe<std::uint32_t>(1));
}

// CiA 301 §7.5.2.13/14: any value other than the signature is refused with 08000020h and
// nothing is written; an unknown sub-index gives 06090011h.
TEST_F(ParameterStoreTest, WrongSignatureAbortsAndStoresNothing) {
  auto device = Boot();
  ChangeEverything(device->od);
  EXPECT_EQ(device->od.Write(0x1010, 1, EncodeLe<std::uint32_t>(0x65766174)), SdoAbort::kCannotTransfer);
  EXPECT_EQ(device->od.Write(0x1010, 1, Load()), SdoAbort::kCannotTransfer);
  EXPECT_EQ(device->od.Write(0x1011, 1, Save()), SdoAbort::kCannotTransfer);
  EXPECT_EQ(device->od.Write(0x1010, 1, EncodeLe<std::uint32_t>(1)), SdoAbort::kCannotTransfer);
  EXPECT_EQ(device->od.Write(0x1010, 5, Save()), SdoAbort::kNoSubIndex);
  EXPECT_EQ(device->od.Write(0x1010, 0, Bytes{1}), SdoAbort::kReadOnly);
  EXPECT_EQ(device->od.Write(0x1010, 1, Bytes{0x73, 0x61, 0x76}), SdoAbort::kLengthTooLow);
  EXPECT_FALSE(fs::exists(dir_));
  EXPECT_EQ(device->store->Save(0), SdoAbort::kNoSubIndex);
  EXPECT_EQ(device->store->Save(128), SdoAbort::kNoSubIndex);
  EXPECT_EQ(device->store->MarkRestoreDefaults(0), SdoAbort::kNoSubIndex);
}

// CiA 301 §7.5.2.13: sub 2 communication (1000h–1FFFh), sub 3 application (6000h–9FFFh),
// sub 4 manufacturer (2000h–5FFFh here) are stored independently.
TEST_F(ParameterStoreTest, GroupsAreStoredIndependently) {
  {
    auto device = Boot();
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 2, Save()), SdoAbort::kNone);
  }
  {
    auto device = Boot();
    ExpectCommChanged(device->od, true);
    ExpectMfrChanged(device->od, false);
    ExpectAppChanged(device->od, false);
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 3, Save()), SdoAbort::kNone);
  }
  {
    auto device = Boot();
    ExpectCommChanged(device->od, true);
    ExpectMfrChanged(device->od, false);
    ExpectAppChanged(device->od, true);
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 4, Save()), SdoAbort::kNone);
  }
  auto device = Boot();
  ExpectCommChanged(device->od, true);
  ExpectMfrChanged(device->od, true);
  ExpectAppChanged(device->od, true);
}

// The stack applies ranges: reset communication only re-applies 1000h–1FFFh.
TEST_F(ParameterStoreTest, ApplyStoredOnlyTouchesTheRequestedRange) {
  {
    auto device = Boot();
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 1, Save()), SdoAbort::kNone);
  }
  ObjectDictionary od;
  BuildDictionary(od);
  ParameterStore store(od, dir_);
  od.RestoreDefaults(0x1000, 0xFFFF, 5);
  auto report = store.ApplyStored(0x1000, 0x1FFF, 5);
  EXPECT_TRUE(report.Clean());
  EXPECT_EQ(report.files_applied, std::vector<fs::path>{File("params-comm.bin")});
  ExpectCommChanged(od, true);
  ExpectMfrChanged(od, false);
  ExpectAppChanged(od, false);
  report = store.ApplyStored(0x2000, 0xFFFF, 5);
  EXPECT_EQ(report.files_applied.size(), 2u);
  ExpectMfrChanged(od, true);
  ExpectAppChanged(od, true);
}

// Stored values reach the services: ApplyStored writes through the dictionary, so listeners run.
TEST_F(ParameterStoreTest, ApplyingRunsListeners) {
  {
    auto device = Boot();
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 2, Save()), SdoAbort::kNone);
  }
  ObjectDictionary od;
  BuildDictionary(od);
  ParameterStore store(od, dir_);
  std::vector<std::uint64_t> seen;
  od.Find(0x1017, 0)->AddListener(
      [&](SubObject& sub, Origin) { seen.push_back(DecodeUnsignedLe(sub.value)); });
  od.RestoreDefaults(0x1000, 0xFFFF, 5);
  store.ApplyStored(0x1000, 0xFFFF, 5);
  EXPECT_EQ(seen, std::vector<std::uint64_t>{250});
}

// CiA 301 §7.5.2.14: "load" discards the stored values; they stay in use until the next reset,
// after which the defaults apply (the manuals: "takes effect only after a reset").
TEST_F(ParameterStoreTest, RestoreDefaultsTakesEffectAfterTheNextReset) {
  {
    auto device = Boot();
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 1, Save()), SdoAbort::kNone);
  }
  {
    auto device = Boot();
    ExpectCommChanged(device->od, true);
    ASSERT_EQ(device->od.Write(0x1011, 1, Load()), SdoAbort::kNone);
    ExpectCommChanged(device->od, true);  // no immediate effect
    ExpectAppChanged(device->od, true);
  }
  auto device = Boot();
  EXPECT_TRUE(device->report.Clean());
  ExpectCommChanged(device->od, false);
  ExpectMfrChanged(device->od, false);
  ExpectAppChanged(device->od, false);
}

TEST_F(ParameterStoreTest, RestoreDefaultsOfOneGroupKeepsTheOthers) {
  {
    auto device = Boot();
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 1, Save()), SdoAbort::kNone);
    ASSERT_EQ(device->od.Write(0x1011, 3, Load()), SdoAbort::kNone);
  }
  auto device = Boot();
  ExpectCommChanged(device->od, true);
  ExpectMfrChanged(device->od, true);
  ExpectAppChanged(device->od, false);
  EXPECT_FALSE(fs::exists(File("params-app.bin")));
}

// "COB-IDs follow LSS node-ID changes" (manuals): a COB-ID that is still its "$NODEID+x" default
// (also with other flag bits, e.g. a PDO switched off) is stored node-ID relative; a COB-ID set
// to some other CAN-ID is stored as it is.
TEST_F(ParameterStoreTest, NodeIdRelativeCobIdsFollowANewNodeId) {
  {
    auto device = Boot(5);
    EXPECT_EQ(device->od.GetUnsigned(0x1800, 1), 0x40000185u);
    ASSERT_EQ(device->od.Write(0x1400, 1, EncodeLe<std::uint32_t>(0xC0000205)),
              SdoAbort::kNone);  // RPDO1 off
    ASSERT_EQ(device->od.Write(0x1801, 1, EncodeLe<std::uint32_t>(0x40000391)), SdoAbort::kNone);  // fixed ID
    ASSERT_EQ(device->od.Write(0x1010, 2, Save()), SdoAbort::kNone);
  }
  auto device = Boot(9);
  EXPECT_TRUE(device->report.Clean()) << device->report.ToString();
  EXPECT_EQ(device->od.GetUnsigned(0x1800, 1), 0x40000189u);
  EXPECT_EQ(device->od.GetUnsigned(0x1400, 1), 0xC0000209u);
  EXPECT_EQ(device->od.GetUnsigned(0x1801, 1), 0x40000391u);
}

// A damaged file is reported with its name and reason and ignored as a whole: the defaults stay,
// the other groups still load, nothing crashes.
struct Damage {
  const char* name;
  void (*apply)(Bytes&);
  StoreProblem expected;
};

class DamagedFileTest : public ParameterStoreTest, public ::testing::WithParamInterface<Damage> {};

TEST_P(DamagedFileTest, IsReportedAndIgnored) {
  {
    auto device = Boot();
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 1, Save()), SdoAbort::kNone);
  }
  Bytes bytes = ReadRaw(File("params-comm.bin"));
  ASSERT_GT(bytes.size(), 40u);
  GetParam().apply(bytes);
  WriteRaw(File("params-comm.bin"), bytes);

  auto device = Boot();
  ASSERT_EQ(device->report.issues.size(), 1u) << device->report.ToString();
  const auto& issue = device->report.issues[0];
  EXPECT_EQ(issue.file, File("params-comm.bin"));
  EXPECT_EQ(issue.problem, GetParam().expected) << issue.ToString();
  EXPECT_EQ(issue.index, 0);
  EXPECT_NE(device->report.ToString().find("params-comm.bin"), std::string::npos);
  ExpectCommChanged(device->od, false);
  EXPECT_EQ(device->od.GetUnsigned(0x1800, 1), 0x40000185u);
  ExpectMfrChanged(device->od, true);
  ExpectAppChanged(device->od, true);
}

INSTANTIATE_TEST_SUITE_P(
    Files, DamagedFileTest,
    ::testing::Values(Damage{"Truncated", [](Bytes& b) { b.resize(b.size() / 2); }, StoreProblem::kTruncated},
                      Damage{"TruncatedHeader", [](Bytes& b) { b.resize(10); }, StoreProblem::kTruncated},
                      Damage{"FlippedPayloadByte", [](Bytes& b) { b[b.size() - 3] ^= 0x10; },
                             StoreProblem::kBadCrc},
                      Damage{"FlippedCrcByte", [](Bytes& b) { b[13] ^= 0x01; }, StoreProblem::kBadCrc},
                      Damage{"ZeroLength", [](Bytes& b) { b.clear(); }, StoreProblem::kEmpty},
                      Damage{"WrongMagic", [](Bytes& b) { b[0] = 'X'; }, StoreProblem::kBadMagic},
                      Damage{"TextFile", [](Bytes& b) { b = ToBytes("hello, this is not a store file\n"); },
                             StoreProblem::kBadMagic},
                      Damage{"WrongVersion", [](Bytes& b) { b[4] = 99; }, StoreProblem::kBadVersion},
                      Damage{"AppendedBytes", [](Bytes& b) { b.push_back(0); }, StoreProblem::kBadLength},
                      Damage{"OtherGroupsFile",
                             [](Bytes& b) { b[6] = static_cast<std::uint8_t>(StoreGroup::kApplication); },
                             StoreProblem::kForeign}),
    [](const ::testing::TestParamInfo<Damage>& param_info) { return std::string(param_info.param.name); });

// A file written by another device type (1018h product code) is foreign.
TEST_F(ParameterStoreTest, FileOfAnotherDeviceTypeIsForeign) {
  {
    auto device = Boot(5, 0xAA181001);
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 1, Save()), SdoAbort::kNone);
  }
  auto device = Boot();
  ASSERT_EQ(device->report.issues.size(), 3u) << device->report.ToString();
  for (const auto& issue : device->report.issues)
    EXPECT_EQ(issue.problem, StoreProblem::kForeign);
  ExpectCommChanged(device->od, false);
  ExpectMfrChanged(device->od, false);
  ExpectAppChanged(device->od, false);
}

// Every single-byte corruption of a stored file: reported, defaults kept.
TEST_F(ParameterStoreTest, EveryFlippedByteIsReportedAndIgnored) {
  {
    auto device = Boot();
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 3, Save()), SdoAbort::kNone);
  }
  const Bytes good = ReadRaw(File("params-app.bin"));
  ObjectDictionary od;
  BuildDictionary(od);
  ParameterStore store(od, dir_);
  for (std::size_t i = 0; i < good.size(); ++i) {
    Bytes bad = good;
    bad[i] ^= 0xA5;
    WriteRaw(File("params-app.bin"), bad);
    od.RestoreDefaults(0x1000, 0xFFFF, 5);
    auto report = store.ApplyStored(0x1000, 0xFFFF, 5);
    EXPECT_EQ(report.issues.size(), 1u) << "byte " << i;
    ExpectAppChanged(od, false);
  }
}

// A crash between writing the temporary file and the rename leaves "<file>.tmp": it is never
// read, and the next save replaces it.
TEST_F(ParameterStoreTest, StaleTempFileFromACrashIsIgnored) {
  fs::create_directories(dir_);
  WriteRaw(TempPathFor(File("params-comm.bin")), ToBytes("half-written garbage"));
  {
    auto device = Boot();
    EXPECT_TRUE(device->report.Clean()) << device->report.ToString();
    EXPECT_TRUE(device->report.files_applied.empty());
    ExpectCommChanged(device->od, false);
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 2, Save()), SdoAbort::kNone);
    EXPECT_FALSE(fs::exists(TempPathFor(File("params-comm.bin"))));
  }
  // The old, complete file wins over a newer half-written temporary one.
  WriteRaw(TempPathFor(File("params-comm.bin")), Bytes(3000, 0xEE));
  auto device = Boot();
  EXPECT_TRUE(device->report.Clean()) << device->report.ToString();
  ExpectCommChanged(device->od, true);
}

// An entry whose object is gone or has another type or size (new firmware, same state folder)
// is skipped and reported; the rest of the file still applies.
TEST_F(ParameterStoreTest, EntriesThatNoLongerFitAreSkippedAndReported) {
  {
    auto device = Boot();
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x2002, 0, Bytes{77}), SdoAbort::kNone);
    ASSERT_EQ(device->od.Write(0x1010, 4, Save()), SdoAbort::kNone);
  }
  ObjectDictionary od;
  BuildDictionary(od);
  od.objects().erase(0x2002);
  od.AddVar(0x2000, "Mfr word, now 32-bit", DataType::kUnsigned32, Access::kRw, EncodeLe<std::uint32_t>(1));
  od.Find(0x2001, 0)->access = Access::kRo;
  ParameterStore store(od, dir_);
  od.RestoreDefaults(0x1000, 0xFFFF, 5);
  auto report = store.ApplyStored(0x1000, 0xFFFF, 5);
  ASSERT_EQ(report.issues.size(), 3u) << report.ToString();
  EXPECT_EQ(report.issues[0].problem, StoreProblem::kTypeMismatch);
  EXPECT_EQ(report.issues[0].index, 0x2000);
  EXPECT_EQ(report.issues[1].problem, StoreProblem::kNotStorable);
  EXPECT_EQ(report.issues[1].index, 0x2001);
  EXPECT_EQ(report.issues[2].problem, StoreProblem::kNoSuchObject);
  EXPECT_EQ(report.issues[2].index, 0x2002);
  EXPECT_NE(report.ToString().find("2002h.00"), std::string::npos);
  EXPECT_EQ(od.GetUnsigned(0x2000, 0), 1u);
  EXPECT_EQ(od.Find(0x2001, 0)->value, ToBytes("default"));
}

TEST_F(ParameterStoreTest, StoredValueOutsideNewLimitsIsSkipped) {
  {
    auto device = Boot();
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 3, Save()), SdoAbort::kNone);
  }
  ObjectDictionary od;
  BuildDictionary(od);
  od.Find(0x6100, 0)->low_limit = EncodeLe<std::int16_t>(0);
  ParameterStore store(od, dir_);
  od.RestoreDefaults(0x1000, 0xFFFF, 5);
  auto report = store.ApplyStored(0x1000, 0xFFFF, 5);
  ASSERT_EQ(report.issues.size(), 1u) << report.ToString();
  EXPECT_EQ(report.issues[0].problem, StoreProblem::kOutOfRange);
  EXPECT_EQ(od.GetSigned(0x6100, 0), 0);
  EXPECT_EQ(od.GetUnsigned(0x6000, 0), 9u);
}

// CiA 301 §7.5.2.13: a storage failure answers 06060000h (access failed due to a hardware error).
TEST_F(ParameterStoreTest, WriteFailureAnswersHardwareError) {
  fs::create_directories(dir_);
  WriteRaw(dir_ / "not-a-directory", Bytes{1});
  ObjectDictionary od;
  BuildDictionary(od);
  ParameterStore store(od, dir_ / "not-a-directory" / "node5");
  EXPECT_EQ(od.Write(0x1010, 1, Save()), SdoAbort::kHardwareError);
  EXPECT_FALSE(store.LastError().empty());
  EXPECT_EQ(store.Save(2), SdoAbort::kHardwareError);
  EXPECT_FALSE(store.SaveLssConfig(5, 4));
  // Loading from there reports each group's file as unreadable and keeps the defaults.
  od.RestoreDefaults(0x1000, 0xFFFF, 5);
  auto report = store.ApplyStored(0x1000, 0xFFFF, 5);
  ASSERT_EQ(report.issues.size(), 3u) << report.ToString();
  for (const auto& issue : report.issues)
    EXPECT_EQ(issue.problem, StoreProblem::kIoError);
  ExpectCommChanged(od, false);
}

// A stored file that cannot be read as a regular file (here: a directory in its place).
TEST_F(ParameterStoreTest, UnreadableFileIsReported) {
  fs::create_directories(File("params-mfr.bin"));
  auto device = Boot();
  ASSERT_EQ(device->report.issues.size(), 1u);
  EXPECT_EQ(device->report.issues[0].problem, StoreProblem::kIoError);
}

// CiA 305 store configuration: node-ID and bit timing in their own file.
TEST_F(ParameterStoreTest, LssConfigurationRoundTrips) {
  {
    auto device = Boot();
    EXPECT_FALSE(device->store->LoadLssConfig().has_value());
    EXPECT_TRUE(device->store->SaveLssConfig(0x20, 2));
  }
  auto device = Boot();
  auto config = device->store->LoadLssConfig();
  ASSERT_TRUE(config.has_value());
  EXPECT_EQ(*config, std::make_pair(std::uint8_t{0x20}, std::uint8_t{2}));
  EXPECT_TRUE(device->store->SaveLssConfig(0xFF, 4));  // non-configured is a valid stored state
  EXPECT_EQ(device->store->LoadLssConfig(), std::make_pair(std::uint8_t{0xFF}, std::uint8_t{4}));
  // 1011h "restore all" leaves the LSS configuration alone.
  ASSERT_EQ(device->od.Write(0x1011, 1, Load()), SdoAbort::kNone);
  EXPECT_TRUE(device->store->LoadLssConfig().has_value());
}

TEST_F(ParameterStoreTest, DamagedOrInvalidLssConfigurationIsReported) {
  auto device = Boot();
  ASSERT_TRUE(device->store->SaveLssConfig(0x20, 2));
  Bytes bytes = ReadRaw(File("lss.bin"));
  bytes.back() ^= 0xFF;
  WriteRaw(File("lss.bin"), bytes);
  LoadReport report;
  EXPECT_FALSE(device->store->LoadLssConfig(&report).has_value());
  ASSERT_EQ(report.issues.size(), 1u);
  EXPECT_EQ(report.issues[0].problem, StoreProblem::kBadCrc);
  // Well-formed but out of range: node-ID 0, bit timing 5 (reserved).
  ASSERT_TRUE(device->store->SaveLssConfig(0, 4));
  report = {};
  EXPECT_FALSE(device->store->LoadLssConfig(&report).has_value());
  ASSERT_EQ(report.issues.size(), 1u);
  EXPECT_EQ(report.issues[0].problem, StoreProblem::kMalformed);
  ASSERT_TRUE(device->store->SaveLssConfig(5, 5));
  EXPECT_FALSE(device->store->LoadLssConfig().has_value());
}

// Exclude() keeps a device's command objects out of the file.
TEST_F(ParameterStoreTest, ExcludedObjectsAreNotStored) {
  {
    auto device = Boot();
    device->store->Exclude(0x2000);
    ChangeEverything(device->od);
    ASSERT_EQ(device->od.Write(0x1010, 4, Save()), SdoAbort::kNone);
  }
  auto device = Boot();
  EXPECT_TRUE(device->report.Clean());
  EXPECT_EQ(device->od.GetUnsigned(0x2000, 0), 1000u);
  EXPECT_EQ(device->od.Find(0x2001, 0)->value, ToBytes("changed text"));
}

}  // namespace
}  // namespace canfleet::canopen
