#pragma once
/// @file Store and restore parameters: CiA 301 v4.2 §7.5.2.13 (1010h store parameters) and
/// §7.5.2.14 (1011h restore default parameters), and the CiA 305 persistent LSS configuration,
/// kept as files in a per-node state directory.
///
/// Groups (1010h/1011h sub-index → object range → file in the state directory):
///
/// | sub   | group          | objects         | file                                |
/// |-------|----------------|-----------------|-------------------------------------|
/// | 1     | all            | the three below | all three files, in one transaction |
/// | 2     | communication  | 1000h–1FFFh     | params-comm.bin                     |
/// | 3     | application    | 6000h–9FFFh     | params-app.bin                      |
/// | 4..7F | manufacturer   | 2000h–5FFFh     | params-mfr.bin                      |
///
/// Sub-indexes 2 and 3 and their ranges are CiA 301's; CiA 301 leaves 4..7Fh to the manufacturer,
/// and the five device manuals use exactly sub 4 for "manufacturer" (2000h–5FFFh here). Objects
/// A000h–FFFFh belong to no group and are never stored. The LSS configuration lives in `lss.bin`
/// and is written only by LSS store configuration; 1011h does not touch it (the node keeps the
/// node-ID and bit rate a master gave it).
///
/// What is stored: every sub-object of the group's range whose access type lets the network write
/// it (rw, rww, rwr, wo), except 1003h (writing it is a command: clear the error history), 1010h,
/// 1011h and whatever Exclude() names. COB-ID-like values whose default is "$NODEID+x" and that
/// still carry that default CAN-ID are stored node-ID relative, so they follow a node-ID change
/// (the manuals: "COB-IDs follow LSS node-ID changes").
///
/// Restoring (1011h) deletes the group's file: the current values stay until the next reset,
/// which then finds no stored values and keeps the defaults (the manuals: restored defaults take
/// effect only after a reset).
///
/// Crash safety: after a kill or a power cut at any moment, every group comes from the same save
/// (the old one or the new one); a restore all likewise removes all three files or none. A single
/// group (sub 2..7Fh) is one file, replaced atomically (atomic_file.hpp). Sub 1 changes the three files in
/// one transaction (store_transaction.hpp: staged "<file>.new" files, then the commit record
/// "store-commit.bin", then the renames); the constructor completes or discards a transaction
/// that a kill interrupted before anything reads the directory, and the next ApplyStored report
/// says which it did.
///
/// Storage is synchronous: the node is single-threaded and a file is a few KB, so a 1010h write
/// returns once the files are durable.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "node/canopen/od/object_dictionary.hpp"
#include "node/canopen/storage/store_file.hpp"
#include "node/canopen/storage/store_transaction.hpp"

namespace canfleet::canopen {

/// 1010h write value "save" (bytes 73h 61h 76h 65h), CiA 301 §7.5.2.13.
inline constexpr std::uint32_t kSaveSignature = 0x65766173;
/// 1011h write value "load" (bytes 6Ch 6Fh 61h 64h), CiA 301 §7.5.2.14.
inline constexpr std::uint32_t kLoadSignature = 0x64616F6C;

/// One file's or entry's problem found while loading.
struct StoreIssue {
  std::filesystem::path file;
  StoreProblem problem = StoreProblem::kMalformed;
  /// The entry's object for entry problems; 0 for problems of the whole file.
  std::uint16_t index = 0;
  std::uint8_t sub_index = 0;
  std::string detail;

  /// "params-comm.bin: CRC mismatch (corrupt): CRC …" or "params-app.bin 6100h.01: data type differs: …".
  std::string ToString() const;
};

/// What ApplyStored did. Problems never stop the node: a bad file is ignored as a whole (the
/// defaults stay), a bad entry is skipped.
struct LoadReport {
  std::vector<std::filesystem::path> files_applied;  ///< files whose entries were applied
  std::size_t entries_applied = 0;
  std::vector<StoreIssue> issues;
  /// A save all / restore all that a kill interrupted and the store then completed or discarded
  /// (ParameterStore's constructor, or after a failed save). Carried once, by the next
  /// ApplyStored report; kNothing usually.
  TransactionRecovery recovery;

  /// No issue (a recovery is not one: the groups are consistent again).
  bool Clean() const { return issues.empty(); }
  /// Nothing worth a log line: clean and no recovery.
  bool Quiet() const { return Clean() && recovery.outcome == TransactionRecovery::Outcome::kNothing; }
  /// One line for the recovery, if any, and one per issue, for the node's log.
  std::string ToString() const;
};

/// A group's object range and file.
struct StoreGroupInfo {
  StoreGroup group;
  std::uint16_t first;
  std::uint16_t last;
  const char* file_name;
};
/// The three parameter groups, in the order "save all" writes them.
const std::vector<StoreGroupInfo>& ParameterGroups();

class ParameterStore {
 public:
  /// Installs the 1010h/1011h hooks on every existing sub-index ≥ 1 of those objects (call
  /// AddStorageObjects first if the device has none), and settles a save all / restore all that a
  /// kill interrupted (store_transaction.hpp), so that every later read sees all groups from the
  /// same save; the next ApplyStored reports what that did. Applies no stored value yet.
  /// @param od must outlive the store; the hooks capture `this`, so the store must not move.
  /// @param state_dir the node's own directory; created on the first save.
  ParameterStore(ObjectDictionary& od, std::filesystem::path state_dir);
  ParameterStore(const ParameterStore&) = delete;
  ParameterStore& operator=(const ParameterStore&) = delete;

  /// Applies the stored values of the groups overlapping [first, last] (only their objects inside
  /// that range) on top of the current values, through Origin::kDevice writes so listeners run.
  /// Called by the stack after ObjectDictionary::RestoreDefaults at reset node (1000h–FFFFh, or
  /// 2000h–FFFFh then 1000h–1FFFh) and at reset communication (1000h–1FFFh). `node_id` is added to
  /// node-ID relative values and remembered for later saves. Never throws.
  LoadReport ApplyStored(std::uint16_t first, std::uint16_t last, std::uint8_t node_id);

  /// Stores the current values of group `sub` (1 all, 2 comm, 3 application, 4..127 manufacturer).
  /// kNone on success, kNoSubIndex for sub 0 or > 127, kHardwareError (06060000h) if the files
  /// cannot be written (LastError() says why). Sub 1 replaces the three files as one transaction:
  /// after a kill at any moment, or a failure part-way, all three groups come from this save or
  /// all from the previous one, never a mix. kNone means the new files are durable.
  SdoAbort Save(std::uint8_t sub);
  /// Discards the stored values of group `sub` so that the defaults apply after the next reset.
  /// Same return codes as Save; sub 1 removes the three files as one transaction, like Save(1).
  SdoAbort MarkRestoreDefaults(std::uint8_t sub);

  /// CiA 305 store configuration: persists the LSS node-ID and bit timing index in `lss.bin`.
  bool SaveLssConfig(std::uint8_t node_id, std::uint8_t bit_timing_index);
  /// The stored LSS configuration: (node-ID, bit timing index); nullopt if none is stored or the
  /// file is unusable (then `report`, if given, says why).
  std::optional<std::pair<std::uint8_t, std::uint8_t>> LoadLssConfig(LoadReport* report = nullptr) const;

  /// Never store `index` (e.g. a device's command objects in 2000h–5FFFh).
  void Exclude(std::uint16_t index) { excluded_.insert(index); }
  /// The node-ID used to recognise node-ID relative values on the next save (ApplyStored sets it).
  void SetNodeId(std::uint8_t node_id) { node_id_ = node_id; }

  const std::filesystem::path& StateDir() const { return state_dir_; }
  std::filesystem::path PathOf(StoreGroup group) const;
  /// The reason of the last failed Save/MarkRestoreDefaults/SaveLssConfig ("" if none failed).
  const std::string& LastError() const { return last_error_; }

 private:
  bool Storable(const SubObject& sub) const;
  StoreImage Snapshot(const StoreGroupInfo& group);
  void ApplyEntry(const StoreGroupInfo& group, const std::filesystem::path& file, const StoreEntry& entry,
                  std::uint8_t node_id, LoadReport& report);
  std::optional<StoreImage> LoadImage(StoreGroup group, LoadReport& report) const;
  enum class ChangeKind : std::uint8_t { kSave, kRestore };
  SdoAbort Change(std::uint8_t sub, ChangeKind kind);
  SdoAbort SaveGroup(const StoreGroupInfo& group);
  SdoAbort RemoveGroup(const StoreGroupInfo& group);
  SdoAbort SaveAll();
  SdoAbort RestoreAll();
  SdoAbort CommitAll(StoreTransaction& change);
  bool SettleInterruptedChange();
  void ReportRecovery(LoadReport& report);
  void InstallHooks(std::uint16_t index, std::uint32_t signature);
  std::uint32_t VendorId() const;
  std::uint32_t ProductCode() const;

  ObjectDictionary& od_;
  std::filesystem::path state_dir_;
  std::set<std::uint16_t> excluded_;
  std::uint8_t node_id_ = 0;
  std::string last_error_;
  /// A transaction may be left unsettled (an I/O error during Commit or recovery): settle it
  /// before the next read or change of the directory.
  bool settle_needed_ = true;
  /// What the last settling did, for the next ApplyStored report.
  TransactionRecovery unreported_recovery_;
  /// Why the last settling failed ("" if it did not).
  std::string settle_error_;
};

/// Creates 1010h "Store parameters" and 1011h "Restore default parameters" as ARRAYs: sub 0 = 4
/// (U8 ro), subs 1–4 U32 rw reading 1 (1010h bit 0: saves on command only; 1011h bit 0: can
/// restore defaults). Replaces existing objects.
void AddStorageObjects(ObjectDictionary& od);

}  // namespace canfleet::canopen
