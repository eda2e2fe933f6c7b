#include "node/canopen/storage/parameter_store.hpp"

#include <algorithm>
#include <array>
#include <cstdio>

#include "node/canopen/storage/atomic_file.hpp"

namespace canfleet::canopen {

namespace {

constexpr std::uint16_t kStoreIndex = 0x1010;
constexpr std::uint16_t kRestoreIndex = 0x1011;
constexpr std::uint16_t kErrorHistoryIndex = 0x1003;
constexpr std::uint16_t kIdentityIndex = 0x1018;
constexpr const char* kLssFileName = "lss.bin";

std::string Hex4(std::uint16_t index) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04Xh", index);
  return buf;
}

std::string Hex2(std::uint8_t sub) {
  char buf[4];
  std::snprintf(buf, sizeof buf, "%02X", sub);
  return buf;
}

std::uint64_t MaskFor(std::size_t size) {
  return size >= 8 ? ~std::uint64_t{0} : (std::uint64_t{1} << (8 * size)) - 1;
}

/// Size of an integer type (a "$NODEID+x" default only makes sense on integers); nullopt otherwise.
std::optional<std::size_t> IntegerSize(DataType type) {
  if (!IsUnsigned(type) && !IsSigned(type)) return std::nullopt;
  return FixedSize(type);
}

/// If `value` is the "$NODEID+x" default of `sub` for `node_id` (for 32-bit values: apart from
/// the flag bits 29–31 — frame format, RTR, valid — so a PDO switched off or on still follows the
/// node-ID), the value with the node-ID taken off; otherwise nullopt.
std::optional<Bytes> RelativeValue(const SubObject& sub, const Bytes& value, std::uint8_t node_id) {
  if (!sub.default_adds_node_id || node_id < 1 || node_id > 127) return std::nullopt;
  const auto size = IntegerSize(sub.type);
  if (!size || value.size() != *size || sub.default_value.size() != *size) return std::nullopt;
  const std::uint64_t mask = MaskFor(*size);
  const std::uint64_t relative = (DecodeUnsignedLe(value) - node_id) & mask;
  const std::uint64_t compared = *size == 4 ? 0x1FFFFFFFu : mask;
  if ((relative & compared) != (DecodeUnsignedLe(sub.default_value) & compared)) return std::nullopt;
  return EncodeLe(relative, *size);
}

/// The one group of 1010h/1011h sub-index 2..127 (sub 1 is all of them).
const StoreGroupInfo& SingleGroupFor(std::uint8_t sub) {
  const StoreGroup wanted = sub == 2   ? StoreGroup::kCommunication
                            : sub == 3 ? StoreGroup::kApplication
                                       : StoreGroup::kManufacturer;
  const auto& groups = ParameterGroups();
  return *std::find_if(groups.begin(), groups.end(), [wanted](const auto& g) { return g.group == wanted; });
}

}  // namespace

std::string StoreIssue::ToString() const {
  std::string out = file.filename().string();
  if (index != 0) out += " " + Hex4(index) + "." + Hex2(sub_index);
  out += ": ";
  out += canopen::ToString(problem);
  if (!detail.empty()) out += ": " + detail;
  return out;
}

std::string LoadReport::ToString() const {
  std::string out = recovery.ToString();
  if (!out.empty()) out += '\n';
  for (const auto& issue : issues) {
    out += issue.ToString();
    out += '\n';
  }
  return out;
}

const std::vector<StoreGroupInfo>& ParameterGroups() {
  static const std::vector<StoreGroupInfo> groups{
      {StoreGroup::kCommunication, 0x1000, 0x1FFF, "params-comm.bin"},
      {StoreGroup::kManufacturer, 0x2000, 0x5FFF, "params-mfr.bin"},
      {StoreGroup::kApplication, 0x6000, 0x9FFF, "params-app.bin"},
  };
  return groups;
}

ParameterStore::ParameterStore(ObjectDictionary& od, std::filesystem::path state_dir)
    : od_(od), state_dir_(std::move(state_dir)) {
  InstallHooks(kStoreIndex, kSaveSignature);
  InstallHooks(kRestoreIndex, kLoadSignature);
  // Here, before anything can read or write a group file: every reader then sees all groups from
  // one save, and no new transaction can stage files that an old commit record would adopt.
  SettleInterruptedChange();
}

// Runs recovery (store_transaction.hpp) and keeps its outcome for the next ApplyStored report: the
// library logs nothing itself. On an I/O error the flag stays set, so the next access retries
// instead of reading a half-applied change or starting a new one on top of it.
bool ParameterStore::SettleInterruptedChange() {
  TransactionRecovery recovery;
  const auto ec = RecoverStoreTransaction(state_dir_, recovery);
  if (recovery.outcome != TransactionRecovery::Outcome::kNothing) {
    // Only "save all" stages files, so staged files without a valid record were a save all.
    const bool staged = std::any_of(recovery.files.begin(), recovery.files.end(),
                                    [](const std::string& name) { return name.ends_with(kStagedSuffix); });
    if (recovery.operation.empty() && staged) recovery.operation = "save all";
    unreported_recovery_ = std::move(recovery);
  }
  settle_needed_ = static_cast<bool>(ec);
  settle_error_ =
      ec ? "could not complete or discard an interrupted save all / restore all: " + ec.message() : "";
  return !ec;
}

void ParameterStore::ReportRecovery(LoadReport& report) {
  if (settle_needed_) SettleInterruptedChange();
  report.recovery = std::exchange(unreported_recovery_, {});
  if (!settle_error_.empty())
    report.issues.push_back({state_dir_ / kCommitRecordName, StoreProblem::kIoError, 0, 0, settle_error_});
}

std::filesystem::path ParameterStore::PathOf(StoreGroup group) const {
  if (group == StoreGroup::kLss) return state_dir_ / kLssFileName;
  for (const auto& g : ParameterGroups()) {
    if (g.group == group) return state_dir_ / g.file_name;
  }
  return state_dir_ / "unknown.bin";
}

std::uint32_t ParameterStore::VendorId() const {
  return static_cast<std::uint32_t>(od_.GetUnsigned(kIdentityIndex, 1));
}
std::uint32_t ParameterStore::ProductCode() const {
  return static_cast<std::uint32_t>(od_.GetUnsigned(kIdentityIndex, 2));
}

// CiA 301 §7.5.2.13/§7.5.2.14: writing the signature to a sub-index stores (restores) its group;
// any other value is refused with 08000020h. Reading gives 1: 1010h bit 0 "saves on command",
// 1011h bit 0 "restores defaults". The work happens in the validator so its result can become
// the SDO answer (06060000h on an I/O failure). Device-origin writes skip validators: device code
// calls Save()/MarkRestoreDefaults() directly.
void ParameterStore::InstallHooks(std::uint16_t index, std::uint32_t signature) {
  Object* object = od_.Find(index);
  if (!object) return;
  const bool store = index == kStoreIndex;
  auto read_as_one = [](SubObject& sub) {
    sub.value = EncodeLe<std::uint32_t>(1, FixedSize(sub.type).value_or(4));
  };
  for (auto& [sub_index, sub] : object->subs) {
    if (sub_index == 0) continue;
    sub.AddValidator(
        [this, signature, store](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
          if (data.size() != 4 || DecodeUnsignedLe(data) != signature) return SdoAbort::kCannotTransfer;
          return store ? Save(s.sub_index) : MarkRestoreDefaults(s.sub_index);
        });
    sub.AddListener([read_as_one](SubObject& s, Origin) { read_as_one(s); });
    sub.AddReadHook([read_as_one](SubObject& s, Origin) {
      read_as_one(s);
      return SdoAbort::kNone;
    });
    read_as_one(sub);
  }
}

bool ParameterStore::Storable(const SubObject& sub) const {
  if (sub.index == kStoreIndex || sub.index == kRestoreIndex || sub.index == kErrorHistoryIndex) return false;
  if (excluded_.count(sub.index) != 0) return false;
  return IsWritable(sub.access) && IsKnown(sub.type);
}

StoreImage ParameterStore::Snapshot(const StoreGroupInfo& group) {
  StoreImage image;
  image.group = group.group;
  image.vendor_id = VendorId();
  image.product_code = ProductCode();
  auto& objects = od_.objects();
  for (auto it = objects.lower_bound(group.first); it != objects.end() && it->first <= group.last; ++it) {
    for (auto& [sub_index, sub] : it->second.subs) {
      if (!Storable(sub)) continue;
      StoreEntry entry;
      entry.index = sub.index;
      entry.sub_index = sub_index;
      entry.type = sub.type;
      // Through Read so that values computed by read hooks are stored as a client would see them;
      // a hook that refuses (e.g. "no data") means there is nothing to store.
      if (od_.Read(sub.index, sub_index, entry.value, Origin::kDevice) != SdoAbort::kNone) continue;
      if (entry.value.size() > 0xFFFF) continue;
      if (auto relative = RelativeValue(sub, entry.value, node_id_)) {
        entry.value = std::move(*relative);
        entry.node_id_relative = true;
      }
      image.entries.push_back(std::move(entry));
    }
  }
  return image;
}

SdoAbort ParameterStore::SaveGroup(const StoreGroupInfo& group) {
  const auto path = PathOf(group.group);
  const Bytes bytes = EncodeStoreFile(Snapshot(group));
  if (auto ec = WriteFileAtomically(path, bytes)) {
    last_error_ = path.string() + ": " + ec.message();
    return SdoAbort::kHardwareError;
  }
  return SdoAbort::kNone;
}

// A failed Commit may leave staged files or a commit record: settle them right away (the groups
// are then all old or all new, and the next report says which), or, if even that fails, before
// the next access.
SdoAbort ParameterStore::CommitAll(StoreTransaction& change) {
  if (auto ec = change.Commit()) {
    last_error_ = change.FailedPath().string() + ": " + ec.message();
    SettleInterruptedChange();
    return SdoAbort::kHardwareError;
  }
  return SdoAbort::kNone;
}

SdoAbort ParameterStore::SaveAll() {
  StoreTransaction change(state_dir_, "save all");
  for (const auto& group : ParameterGroups())
    change.Replace(group.file_name, EncodeStoreFile(Snapshot(group)));
  return CommitAll(change);
}

SdoAbort ParameterStore::RestoreAll() {
  StoreTransaction change(state_dir_, "restore all");
  for (const auto& group : ParameterGroups())
    change.Remove(group.file_name);
  return CommitAll(change);
}

SdoAbort ParameterStore::RemoveGroup(const StoreGroupInfo& group) {
  const auto path = PathOf(group.group);
  if (auto ec = RemoveFileDurably(path)) {
    last_error_ = path.string() + ": " + ec.message();
    return SdoAbort::kHardwareError;
  }
  return SdoAbort::kNone;
}

SdoAbort ParameterStore::Save(std::uint8_t sub) {
  return Change(sub, ChangeKind::kSave);
}

SdoAbort ParameterStore::MarkRestoreDefaults(std::uint8_t sub) {
  return Change(sub, ChangeKind::kRestore);
}

// What 1010h and 1011h share: the sub-index check, settling a transaction an I/O error left
// behind before touching the files again, and LastError(). One group is one file, which
// WriteFileAtomically/RemoveFileDurably change all-or-nothing already; all groups take a
// transaction.
SdoAbort ParameterStore::Change(std::uint8_t sub, ChangeKind kind) {
  if (sub == 0 || sub > 127) return SdoAbort::kNoSubIndex;
  if (settle_needed_ && !SettleInterruptedChange()) {
    last_error_ = settle_error_;
    return SdoAbort::kHardwareError;
  }
  const bool save = kind == ChangeKind::kSave;
  SdoAbort rc = SdoAbort::kNone;
  if (sub == 1) {
    rc = save ? SaveAll() : RestoreAll();
  } else {
    const StoreGroupInfo& group = SingleGroupFor(sub);
    rc = save ? SaveGroup(group) : RemoveGroup(group);
  }
  if (rc == SdoAbort::kNone) last_error_.clear();
  return rc;
}

std::optional<StoreImage> ParameterStore::LoadImage(StoreGroup group, LoadReport& report) const {
  const auto path = PathOf(group);
  Bytes bytes;
  if (auto ec = ReadWholeFile(path, kStoreMaxFileSize, bytes)) {
    if (ec == std::errc::no_such_file_or_directory) return std::nullopt;  // nothing stored: normal
    const auto problem = ec == std::errc::file_too_large ? StoreProblem::kTooLarge : StoreProblem::kIoError;
    report.issues.push_back({path, problem, 0, 0, ec.message()});
    return std::nullopt;
  }
  auto decoded = DecodeStoreFile(bytes, group);
  if (!decoded.image) {
    report.issues.push_back({path, decoded.problem, 0, 0, std::move(decoded.detail)});
    return std::nullopt;
  }
  if (decoded.image->vendor_id != VendorId() || decoded.image->product_code != ProductCode()) {
    char detail[96];
    std::snprintf(detail, sizeof detail, "written by vendor %08Xh product %08Xh, this device is %08Xh %08Xh",
                  decoded.image->vendor_id, decoded.image->product_code, VendorId(), ProductCode());
    report.issues.push_back({path, StoreProblem::kForeign, 0, 0, detail});
    return std::nullopt;
  }
  return std::move(decoded.image);
}

void ParameterStore::ApplyEntry(const StoreGroupInfo& group, const std::filesystem::path& file,
                                const StoreEntry& entry, std::uint8_t node_id, LoadReport& report) {
  auto issue = [&](StoreProblem problem, std::string detail = {}) {
    report.issues.push_back({file, problem, entry.index, entry.sub_index, std::move(detail)});
  };
  if (entry.index < group.first || entry.index > group.last) return issue(StoreProblem::kOutsideGroup);
  SubObject* sub = od_.Find(entry.index, entry.sub_index);
  if (!sub) return issue(StoreProblem::kNoSuchObject);
  if (sub->type != entry.type) {
    return issue(StoreProblem::kTypeMismatch, std::string("stored ") + std::string(ToString(entry.type)) +
                                                  ", object is " + std::string(ToString(sub->type)));
  }
  const auto size = FixedSize(sub->type);
  if (size && entry.value.size() != *size) {
    return issue(StoreProblem::kSizeMismatch,
                 std::to_string(entry.value.size()) + " bytes, type needs " + std::to_string(*size));
  }
  if (!Storable(*sub)) return issue(StoreProblem::kNotStorable, std::string(ToString(sub->access)));

  Bytes value = entry.value;
  if (entry.node_id_relative) {
    const auto int_size = IntegerSize(sub->type);
    if (!int_size) return issue(StoreProblem::kMalformed, "node-ID relative flag on a non-integer value");
    value = EncodeLe((DecodeUnsignedLe(value) + node_id) & MaskFor(*int_size), *int_size);
  }
  if (!IsVariableLength(sub->type)) {
    if ((sub->high_limit && CompareNumeric(sub->type, value, *sub->high_limit) > 0) ||
        (sub->low_limit && CompareNumeric(sub->type, value, *sub->low_limit) < 0)) {
      return issue(StoreProblem::kOutOfRange, FormatValue(sub->type, value));
    }
  }
  if (sub->value != value) {
    // Origin::kDevice: the value was accepted once already; SDO-only sequencing rules (e.g. a PDO
    // mapping written while the PDO is valid) must not block a restore. Listeners still run.
    if (auto rc = od_.Write(*sub, value, Origin::kDevice); rc != SdoAbort::kNone) {
      return issue(StoreProblem::kRejected, Describe(rc));
    }
  }
  ++report.entries_applied;
}

LoadReport ParameterStore::ApplyStored(std::uint16_t first, std::uint16_t last, std::uint8_t node_id) {
  node_id_ = node_id;
  LoadReport report;
  ReportRecovery(report);
  for (const auto& group : ParameterGroups()) {
    if (group.last < first || group.first > last) continue;
    auto image = LoadImage(group.group, report);
    if (!image) continue;
    const auto file = PathOf(group.group);
    for (const auto& entry : image->entries) {
      if (entry.index < first || entry.index > last) continue;
      ApplyEntry(group, file, entry, node_id, report);
    }
    report.files_applied.push_back(file);
  }
  return report;
}

bool ParameterStore::SaveLssConfig(std::uint8_t node_id, std::uint8_t bit_timing_index) {
  StoreImage image;
  image.group = StoreGroup::kLss;
  image.vendor_id = VendorId();
  image.product_code = ProductCode();
  image.lss = {node_id, bit_timing_index};
  const auto path = PathOf(StoreGroup::kLss);
  if (auto ec = WriteFileAtomically(path, EncodeStoreFile(image))) {
    last_error_ = path.string() + ": " + ec.message();
    return false;
  }
  last_error_.clear();
  return true;
}

std::optional<std::pair<std::uint8_t, std::uint8_t>> ParameterStore::LoadLssConfig(LoadReport* report) const {
  LoadReport local;
  LoadReport& out = report ? *report : local;
  auto image = LoadImage(StoreGroup::kLss, out);
  if (!image) return std::nullopt;
  const auto [node_id, bit_timing] = image->lss;
  // Only what the LSS slave itself accepts (CiA 305: node-ID 1..127 or FFh; CiA 301 bit timing
  // table indexes 0..8 without the reserved 5) may come back from a file.
  const bool node_ok = (node_id >= 1 && node_id <= 127) || node_id == 0xFF;
  const bool timing_ok = bit_timing <= 8 && bit_timing != 5;
  if (!node_ok || !timing_ok) {
    out.issues.push_back(
        {PathOf(StoreGroup::kLss), StoreProblem::kMalformed, 0, 0,
         "node-ID " + std::to_string(node_id) + ", bit timing index " + std::to_string(bit_timing)});
    return std::nullopt;
  }
  return std::make_pair(node_id, bit_timing);
}

void AddStorageObjects(ObjectDictionary& od) {
  auto make = [&od](std::uint16_t index, const char* name, const std::array<const char*, 4>& sub_names) {
    Object object;
    object.index = index;
    object.name = name;
    object.code = ObjectCode::kArray;
    SubObject count;
    count.name = "Highest sub-index supported";
    count.type = DataType::kUnsigned8;
    count.access = Access::kRo;
    count.default_value = {4};
    object.subs.emplace(0, std::move(count));
    for (std::uint8_t i = 1; i <= 4; ++i) {
      SubObject sub;
      sub.name = sub_names[i - 1];
      sub.type = DataType::kUnsigned32;
      sub.access = Access::kRw;
      sub.default_value = EncodeLe<std::uint32_t>(1);
      object.subs.emplace(i, std::move(sub));
    }
    od.Add(std::move(object));
  };
  make(kStoreIndex, "Store parameters",
       {"Save all parameters", "Save communication parameters", "Save application parameters",
        "Save manufacturer defined parameters"});
  make(kRestoreIndex, "Restore default parameters",
       {"Restore all default parameters", "Restore communication default parameters",
        "Restore application default parameters", "Restore manufacturer defined default parameters"});
}

}  // namespace canfleet::canopen
