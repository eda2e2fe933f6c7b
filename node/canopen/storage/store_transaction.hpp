#pragma once
/// @file All-or-nothing changes of several files in one directory: 1010h sub 1 "save all" (the
/// three parameter group files) and 1011h sub 1 "restore all" (removing them). Each file alone is
/// replaced atomically (atomic_file.hpp), but a process killed between two of them would come back
/// with groups from different saves. A small redo journal closes that gap.
///
/// StoreTransaction::Commit, each step durable before the next one starts:
///
///   1. stage   every replaced file's new content goes to "<name>.new" (written and fsync'ed),
///              then the directory is fsync'ed, so the staged files exist for sure before
///              anything refers to them.
///   2. commit  the commit record "store-commit.bin" (format below) lists the actions: replace
///              NAME, remove NAME. It is written with WriteFileAtomically, so it is either
///              absent or complete. Its rename is the moment the change happens: before it the
///              old files count, after it the new ones, however many are renamed yet.
///   3. apply   every "<name>.new" is renamed over "<name>", every removed file is unlinked; the
///              directory is fsync'ed.
///   4. forget  the commit record is removed durably.
///
/// RecoverStoreTransaction, run before anything reads the directory, finishes whatever a kill
/// left behind:
///
///   - a valid commit record: roll forward, i.e. apply every action again (a replace whose
///     "<name>.new" is gone was renamed before the kill, a removed file that is gone was removed),
///     sync, forget.
///   - no commit record, or one that does not decode (torn, CRC mismatch): roll back, i.e. remove
///     every staged "*.new" file, the record's unfinished "store-commit.bin.tmp" and the bad
///     record. The real files were never touched, since nothing is renamed before a complete
///     record exists.
///
/// Both directions only ever move towards the same end state, so a kill during recovery is
/// recovered from by the next recovery (idempotent). One change at a time per directory: the
/// directory belongs to one node, which is single-threaded.
///
/// Commit record, all numbers little-endian:
///
///     offset size  header
///          0    4  magic "CFTX" (43h 46h 54h 58h)
///          4    2  format version (kCommitRecordVersion)
///          6    2  reserved, 0
///          8    4  payload length in bytes (the file is exactly 16 + length bytes)
///         12    4  CRC-32 (Crc32, store_file.hpp) of the payload
///
///     payload
///          0    1  operation name length m, then m bytes of name (for the log: "save all")
///          …    1  action count n, then n actions, each:
///                    1  action (FileAction)
///                    1  file name length k, then k bytes of file name
///
/// File names are plain names inside the directory (not empty, no '/', no NUL, not "." or ".."),
/// so even a record that passes the CRC by chance cannot make recovery touch anything else.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <system_error>
#include <vector>

#include "node/canopen/od/value.hpp"

namespace canfleet::canopen {

/// The commit record's file name in the directory.
inline constexpr const char* kCommitRecordName = "store-commit.bin";
/// What Commit appends to a file name for its staged new content.
inline constexpr const char* kStagedSuffix = ".new";
inline constexpr std::uint16_t kCommitRecordVersion = 1;

/// "<path>.new": where Commit stages the new content of `path`.
std::filesystem::path StagedPathFor(const std::filesystem::path& path);

enum class FileAction : std::uint8_t {
  kReplace = 1,  ///< rename "<name>.new" over "<name>"
  kRemove = 2,   ///< unlink "<name>"
};

struct CommittedAction {
  FileAction action = FileAction::kReplace;
  std::string file_name;  ///< a plain name inside the directory
  friend bool operator==(const CommittedAction&, const CommittedAction&) = default;
};

/// The decoded commit record.
struct CommitRecord {
  std::string operation;  ///< what the change is, for the log ("save all", "restore all")
  std::vector<CommittedAction> actions;
  friend bool operator==(const CommitRecord&, const CommitRecord&) = default;
};

/// Encodes a record. Names and the operation must be at most 255 bytes, and at most 255 actions.
Bytes EncodeCommitRecord(const CommitRecord& record);
/// Decodes and checks a whole record; nullopt if it is torn or corrupt (then `why`, if given,
/// says how). Never throws, never reads outside `bytes`.
std::optional<CommitRecord> DecodeCommitRecord(std::span<const std::uint8_t> bytes,
                                               std::string* why = nullptr);

/// One multi-file change: plan it with Replace/Remove, then Commit.
class StoreTransaction {
 public:
  /// @param dir the directory holding the files; created by Commit if missing.
  /// @param operation what the change is, kept in the commit record for the log.
  StoreTransaction(std::filesystem::path dir, std::string operation);

  /// `file_name` (a plain name in the directory) will hold `content`.
  void Replace(std::string file_name, Bytes content);
  /// `file_name` will be gone.
  void Remove(std::string file_name);

  /// Carries out every planned action or none (steps 1-4 of the file comment). Removing files
  /// that do not exist is no action; a change without actions writes nothing. On an error the
  /// directory may still hold staged files or a commit record: run RecoverStoreTransaction before
  /// the next read or change of the directory; it settles the change one way or the other.
  std::error_code Commit();
  /// The file the last failed Commit was working on.
  const std::filesystem::path& FailedPath() const { return failed_path_; }

 private:
  struct PlannedAction {
    CommittedAction what;
    Bytes content;  ///< kReplace only
  };
  void DropRemovalsOfMissingFiles();
  std::error_code Stage();
  CommitRecord Record() const;
  std::error_code Fail(std::filesystem::path path, std::error_code ec);

  std::filesystem::path dir_;
  std::string operation_;
  std::vector<PlannedAction> planned_;
  std::filesystem::path failed_path_;
};

/// What RecoverStoreTransaction did.
struct TransactionRecovery {
  enum class Outcome : std::uint8_t {
    kNothing,    ///< no interrupted change found
    kCompleted,  ///< a committed change was rolled forward: the new files count
    kDiscarded,  ///< an uncommitted change was rolled back: the old files count
  };
  Outcome outcome = Outcome::kNothing;
  /// From the commit record; empty when there was none that decoded.
  std::string operation;
  /// kCompleted: the files still replaced or removed now (the kill came before them).
  /// kDiscarded: the staged files (and the record's unfinished temporary file) removed.
  std::vector<std::string> files;
  /// kDiscarded: why the commit record was unusable; empty if there was none.
  std::string record_problem;

  /// "completed an interrupted save all (…)" / "discarded an unfinished save all (…)"; "" for kNothing.
  std::string ToString() const;
};

/// Settles a change that a kill (or an I/O error in Commit) left in `dir`: roll forward with a
/// valid commit record, roll back without one (file comment). Idempotent; cheap when there is
/// nothing to do (one failed open, one directory scan); a missing `dir` is nothing to do.
/// An error (e.g. the commit record exists but cannot be read) leaves the directory as it was as
/// far as the undecided part goes: nothing is rolled back on a record that might be valid.
std::error_code RecoverStoreTransaction(const std::filesystem::path& dir, TransactionRecovery& out);

}  // namespace canfleet::canopen
