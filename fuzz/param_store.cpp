// Fuzzes the stored-parameter loader: arbitrary bytes become a store file in a state directory,
// then the node loads it like at power-on (ParameterStore::ApplyStored, LoadLssConfig). Any input
// must give a report, never a crash, a hang or an out-of-bounds read. The same bytes also go to the
// parser of the save-all commit record (store-commit.bin).
//
// Input: byte 0 selects how the rest is used, bytes 1.. are the file.
//   bits 0–1  which file: 0 params-comm.bin, 1 params-mfr.bin, 2 params-app.bin, 3 lss.bin
//   bit 2     reseal: recompute the header's payload length and CRC-32, so that mutations reach the
//             payload parser and the entry checks instead of stopping at the CRC
//   bit 3     with reseal: also put this device's 1018h identity into the payload, so the file is
//             not rejected as foreign
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "node/canopen/storage/parameter_store.hpp"

using namespace canfleet::canopen;

namespace {

constexpr std::uint32_t kVendorId = 0x00000055;
constexpr std::uint32_t kProductCode = 0xAA020411;

SubObject FuzzSub(DataType type, Access access, Bytes default_value, bool adds_node_id = false) {
  SubObject sub;
  sub.type = type;
  sub.access = access;
  sub.default_value = std::move(default_value);
  sub.default_adds_node_id = adds_node_id;
  return sub;
}

/// A dictionary with every kind of entry the loader treats differently: fixed and variable sizes,
/// signed with limits, "$NODEID" COB-IDs, read-only and write-only entries, one per group.
void BuildFuzzDictionary(ObjectDictionary& od) {
  AddStorageObjects(od);
  Object identity;
  identity.index = 0x1018;
  identity.code = ObjectCode::kRecord;
  identity.subs.emplace(0, FuzzSub(DataType::kUnsigned8, Access::kRo, {2}));
  identity.subs.emplace(1, FuzzSub(DataType::kUnsigned32, Access::kRo, EncodeLe<std::uint32_t>(kVendorId)));
  identity.subs.emplace(2,
                        FuzzSub(DataType::kUnsigned32, Access::kRo, EncodeLe<std::uint32_t>(kProductCode)));
  od.Add(std::move(identity));
  od.AddVar(0x1017, "hb", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(0));
  Object tpdo;
  tpdo.index = 0x1800;
  tpdo.code = ObjectCode::kRecord;
  tpdo.subs.emplace(0, FuzzSub(DataType::kUnsigned8, Access::kRo, {5}));
  tpdo.subs.emplace(1,
                    FuzzSub(DataType::kUnsigned32, Access::kRw, EncodeLe<std::uint32_t>(0x40000180), true));
  tpdo.subs.emplace(2, FuzzSub(DataType::kUnsigned8, Access::kRw, {254}));
  tpdo.subs.emplace(5, FuzzSub(DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(100)));
  od.Add(std::move(tpdo));
  od.AddVar(0x2000, "word", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(1000));
  od.AddVar(0x2001, "text", DataType::kVisibleString, Access::kRw, ToBytes("default"));
  od.AddVar(0x2002, "domain", DataType::kDomain, Access::kRw, {});
  od.AddVar(0x2003, "real", DataType::kReal64, Access::kRw, EncodeLe<double>(1.5));
  od.AddVar(0x2004, "signed node", DataType::kInteger8, Access::kRw, {0}).default_adds_node_id = true;
  od.AddVar(0x2100, "status", DataType::kUnsigned8, Access::kRo, {0});
  od.AddVar(0x6000, "bool", DataType::kBoolean, Access::kRww, {0});
  auto& limited = od.AddVar(0x6100, "limited", DataType::kInteger16, Access::kRw, EncodeLe<std::int16_t>(0));
  limited.low_limit = EncodeLe<std::int16_t>(-100);
  limited.high_limit = EncodeLe<std::int16_t>(2000);
  od.AddVar(0x6200, "command", DataType::kUnsigned32, Access::kWo, EncodeLe<std::uint32_t>(0));
  od.AddVar(0x6300, "u64", DataType::kUnsigned64, Access::kRw, EncodeLe<std::uint64_t>(7));
}

/// The state directory of this fuzzing process, removed at exit.
std::filesystem::path* g_state_dir = nullptr;

struct Harness {
  std::filesystem::path dir;
  ObjectDictionary od;
  std::unique_ptr<ParameterStore> store;

  Harness() {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/canfleet-fuzz-param-store-XXXXXX";
    if (::mkdtemp(pattern.data()) == nullptr) std::abort();
    dir = pattern;
    g_state_dir = &dir;
    std::atexit([] {
      std::error_code ec;
      if (g_state_dir) std::filesystem::remove_all(*g_state_dir, ec);
    });
    BuildFuzzDictionary(od);
    store = std::make_unique<ParameterStore>(od, dir);
  }
};

void Reseal(Bytes& file, bool with_identity) {
  if (file.size() < kStoreHeaderSize) return;
  if (with_identity && file.size() >= kStoreHeaderSize + 8) {
    auto id = EncodeLe<std::uint32_t>(kVendorId);
    auto product = EncodeLe<std::uint32_t>(kProductCode);
    std::copy(id.begin(), id.end(), file.begin() + kStoreHeaderSize);
    std::copy(product.begin(), product.end(), file.begin() + kStoreHeaderSize + 4);
  }
  const auto length = static_cast<std::uint32_t>(file.size() - kStoreHeaderSize);
  const auto crc = Crc32(std::span<const std::uint8_t>(file).subspan(kStoreHeaderSize));
  for (std::size_t i = 0; i < 4; ++i) {
    file[8 + i] = static_cast<std::uint8_t>(length >> (8 * i));
    file[12 + i] = static_cast<std::uint8_t>(crc >> (8 * i));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Harness* harness = new Harness;
  if (size < 1) return 0;
  const std::uint8_t mode = data[0];
  Bytes file(data + 1, data + size);
  if (mode & 0x04) Reseal(file, (mode & 0x08) != 0);

  static constexpr StoreGroup kGroups[] = {StoreGroup::kCommunication, StoreGroup::kManufacturer,
                                           StoreGroup::kApplication, StoreGroup::kLss};
  const StoreGroup group = kGroups[mode & 0x03];

  // The parser alone, against every group; whatever it accepts must survive a re-encode unchanged.
  for (auto g : kGroups) {
    auto decoded = DecodeStoreFile(file, g);
    if (!decoded.image) continue;
    auto again = DecodeStoreFile(EncodeStoreFile(*decoded.image), g);
    if (!again.image || again.image->entries != decoded.image->entries ||
        !(again.image->lss == decoded.image->lss))
      std::abort();
  }
  // The save-all commit record's parser (store_transaction.hpp) likewise; it decides what recovery
  // renames and removes, so it must also never accept a name outside the state directory.
  if (auto record = DecodeCommitRecord(file)) {
    for (const auto& action : record->actions) {
      if (action.file_name.find('/') != std::string::npos || action.file_name == "..") std::abort();
    }
    if (DecodeCommitRecord(EncodeCommitRecord(*record)) != record) std::abort();
  }

  // The whole load path through the file system.
  const auto path = harness->store->PathOf(group);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  }
  if (group == StoreGroup::kLss) {
    LoadReport report;
    (void)harness->store->LoadLssConfig(&report);
    (void)report.ToString();
  } else {
    const auto node_id = static_cast<std::uint8_t>(1 + (size % 127));
    harness->od.RestoreDefaults(0x1000, 0xFFFF, node_id);
    auto report = harness->store->ApplyStored(0x1000, 0xFFFF, node_id);
    (void)report.ToString();
  }
  std::filesystem::remove(path);
  return 0;
}
