#include "node/canopen/storage/store_transaction.hpp"

#include <algorithm>
#include <array>

#include "node/canopen/storage/atomic_file.hpp"
#include "node/canopen/storage/le_writer.hpp"
#include "node/canopen/storage/store_file.hpp"

namespace canfleet::canopen {

namespace {

namespace fs = std::filesystem;

constexpr std::array<std::uint8_t, 4> kMagic{'C', 'F', 'T', 'X'};
constexpr std::size_t kHeaderSize = 16;
/// A record names a handful of files; anything bigger is not one of ours.
constexpr std::size_t kMaxRecordSize = 64 * 1024;

using le::Put16;
using le::Put32;

void PutShortString(Bytes& out, const std::string& s) {
  out.push_back(static_cast<std::uint8_t>(s.size()));
  out.insert(out.end(), s.begin(), s.end());
}
std::uint32_t Get32(std::span<const std::uint8_t> p) {
  return static_cast<std::uint32_t>(DecodeUnsignedLe(p.first(4)));
}

/// Bounds-checked reader of the payload: a length byte that points past the end fails instead of
/// reading beyond it.
class PayloadReader {
 public:
  explicit PayloadReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  bool Get8(std::uint8_t& v) {
    if (pos_ >= bytes_.size()) return false;
    v = bytes_[pos_++];
    return true;
  }
  bool GetShortString(std::string& s) {
    std::uint8_t n = 0;
    if (!Get8(n) || n > bytes_.size() - pos_) return false;
    s.assign(bytes_.begin() + static_cast<std::ptrdiff_t>(pos_),
             bytes_.begin() + static_cast<std::ptrdiff_t>(pos_ + n));
    pos_ += n;
    return true;
  }
  bool AtEnd() const { return pos_ == bytes_.size(); }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
};

/// A record may only name plain files inside its own directory.
bool IsPlainFileName(const std::string& name) {
  return !name.empty() && name != "." && name != ".." && name.find('/') == std::string::npos &&
         name.find('\0') == std::string::npos;
}

std::optional<CommitRecord> Reject(std::string* why, std::string reason) {
  if (why) *why = std::move(reason);
  return std::nullopt;
}

std::optional<CommitRecord> DecodePayload(std::span<const std::uint8_t> payload, std::string* why) {
  PayloadReader in(payload);
  CommitRecord record;
  std::uint8_t count = 0;
  if (!in.GetShortString(record.operation) || !in.Get8(count)) return Reject(why, "payload too short");
  for (std::uint8_t i = 0; i < count; ++i) {
    std::uint8_t action = 0;
    CommittedAction entry;
    if (!in.Get8(action) || !in.GetShortString(entry.file_name))
      return Reject(why, "action " + std::to_string(i) + " runs past the end");
    if (action != static_cast<std::uint8_t>(FileAction::kReplace) &&
        action != static_cast<std::uint8_t>(FileAction::kRemove))
      return Reject(why, "action " + std::to_string(i) + " is unknown (" + std::to_string(action) + ")");
    if (!IsPlainFileName(entry.file_name))
      return Reject(why, "action " + std::to_string(i) + " names no plain file");
    entry.action = static_cast<FileAction>(action);
    record.actions.push_back(std::move(entry));
  }
  if (!in.AtEnd()) return Reject(why, "bytes after the last action");
  return record;
}

bool IsMissing(std::error_code ec) {
  // ENOTDIR: a path component is a file, so the directory (and anything in it) does not exist.
  return ec == std::errc::no_such_file_or_directory || ec == std::errc::not_a_directory;
}

/// Step 3, shared by Commit and the roll forward. Safe to repeat: a replace whose staged file is
/// gone, or a removal whose file is gone, was done before. `done` collects what was still to do.
std::error_code ApplyCommitted(const fs::path& dir, const CommitRecord& record,
                               std::vector<std::string>& done) {
  for (const auto& action : record.actions) {
    const auto target = dir / action.file_name;
    const auto ec = action.action == FileAction::kReplace ? RenameFile(StagedPathFor(target), target)
                                                          : RemoveFile(target);
    if (ec == std::errc::no_such_file_or_directory) continue;
    if (ec) return ec;
    done.push_back(action.file_name);
  }
  return SyncDirectory(dir);
}

/// The staged files in `dir` (names ending in kStagedSuffix); a missing `dir` has none.
std::error_code FindStagedFiles(const fs::path& dir, std::vector<std::string>& names) {
  std::error_code ec;
  fs::directory_iterator it(dir, ec);
  if (ec) return IsMissing(ec) ? std::error_code{} : ec;
  const std::string suffix = kStagedSuffix;
  for (; it != fs::directory_iterator(); it.increment(ec)) {
    const std::string name = it->path().filename().string();
    std::error_code type_ec;
    if (name.size() > suffix.size() && name.ends_with(suffix) && it->is_regular_file(type_ec))
      names.push_back(name);
  }
  return ec;
}

std::error_code RollForward(const fs::path& dir, const CommitRecord& record, TransactionRecovery& out) {
  out.outcome = TransactionRecovery::Outcome::kCompleted;
  out.operation = record.operation;
  if (auto ec = ApplyCommitted(dir, record, out.files)) return ec;
  return RemoveFileDurably(dir / kCommitRecordName);
}

/// Removes the record's unfinished temporary file (a kill inside WriteFileAtomically), the staged
/// files and the bad record. Nothing here can make a valid record appear, so a kill part-way
/// leaves a state that the next recovery rolls back again.
std::error_code RollBack(const fs::path& dir, std::string record_problem, TransactionRecovery& out) {
  std::vector<std::string> staged;
  if (auto ec = FindStagedFiles(dir, staged)) return ec;
  const auto record_temp = TempPathFor(dir / kCommitRecordName);
  std::error_code temp_ec;
  const bool has_record_temp = fs::symlink_status(record_temp, temp_ec).type() != fs::file_type::not_found;
  // The usual case: nothing was interrupted.
  if (staged.empty() && record_problem.empty() && !has_record_temp) return {};
  out.outcome = TransactionRecovery::Outcome::kDiscarded;
  out.record_problem = std::move(record_problem);
  if (has_record_temp) {
    if (auto ec = RemoveFile(record_temp); ec && !IsMissing(ec)) return ec;
    out.files.push_back(record_temp.filename().string());
  }
  for (const auto& name : staged) {
    if (auto ec = RemoveFile(dir / name); ec && !IsMissing(ec)) return ec;
    out.files.push_back(name);
  }
  if (auto ec = SyncDirectory(dir)) return ec;
  return RemoveFileDurably(dir / kCommitRecordName);
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& name : names) {
    if (!out.empty()) out += ", ";
    out += name;
  }
  return out;
}

}  // namespace

fs::path StagedPathFor(const fs::path& path) {
  auto staged = path;
  staged += kStagedSuffix;
  return staged;
}

Bytes EncodeCommitRecord(const CommitRecord& record) {
  Bytes payload;
  PutShortString(payload, record.operation);
  payload.push_back(static_cast<std::uint8_t>(record.actions.size()));
  for (const auto& action : record.actions) {
    payload.push_back(static_cast<std::uint8_t>(action.action));
    PutShortString(payload, action.file_name);
  }
  Bytes out(kMagic.begin(), kMagic.end());
  Put16(out, kCommitRecordVersion);
  Put16(out, 0);
  Put32(out, static_cast<std::uint32_t>(payload.size()));
  Put32(out, Crc32(payload));
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

std::optional<CommitRecord> DecodeCommitRecord(std::span<const std::uint8_t> bytes, std::string* why) {
  if (bytes.size() < kHeaderSize) return Reject(why, "shorter than its header (torn)");
  if (!std::equal(kMagic.begin(), kMagic.end(), bytes.begin())) return Reject(why, "not a commit record");
  if (DecodeUnsignedLe(bytes.subspan(4, 2)) != kCommitRecordVersion) return Reject(why, "unknown version");
  if (DecodeUnsignedLe(bytes.subspan(6, 2)) != 0) return Reject(why, "reserved bytes not 0");
  const auto payload = bytes.subspan(kHeaderSize);
  if (Get32(bytes.subspan(8)) != payload.size())
    return Reject(why, "length differs from the header's (torn)");
  if (Get32(bytes.subspan(12)) != Crc32(payload)) return Reject(why, "CRC mismatch (corrupt)");
  return DecodePayload(payload, why);
}

StoreTransaction::StoreTransaction(fs::path dir, std::string operation)
    : dir_(std::move(dir)), operation_(std::move(operation)) {}

void StoreTransaction::Replace(std::string file_name, Bytes content) {
  planned_.push_back({{FileAction::kReplace, std::move(file_name)}, std::move(content)});
}

void StoreTransaction::Remove(std::string file_name) {
  planned_.push_back({{FileAction::kRemove, std::move(file_name)}, {}});
}

std::error_code StoreTransaction::Fail(fs::path path, std::error_code ec) {
  failed_path_ = std::move(path);
  return ec;
}

// Removing what is not there changes nothing; leaving it out spares "restore all" on a node that
// never saved the directory, a record and four fsyncs.
void StoreTransaction::DropRemovalsOfMissingFiles() {
  std::erase_if(planned_, [this](const PlannedAction& planned) {
    std::error_code ec;
    return planned.what.action == FileAction::kRemove &&
           fs::symlink_status(dir_ / planned.what.file_name, ec).type() == fs::file_type::not_found;
  });
}

std::error_code StoreTransaction::Stage() {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) return Fail(dir_, ec);
  for (const auto& planned : planned_) {
    if (planned.what.action != FileAction::kReplace) continue;
    const auto staged = StagedPathFor(dir_ / planned.what.file_name);
    if (auto write_ec = WriteFileDurably(staged, planned.content)) return Fail(staged, write_ec);
  }
  // The record must never become durable before the staged files' directory entries do, or a
  // power cut could keep a record whose "<name>.new" files are gone, which the roll forward would
  // take for already renamed.
  if (auto sync_ec = SyncDirectory(dir_)) return Fail(dir_, sync_ec);
  return {};
}

CommitRecord StoreTransaction::Record() const {
  CommitRecord record;
  record.operation = operation_;
  for (const auto& planned : planned_)
    record.actions.push_back(planned.what);
  return record;
}

std::error_code StoreTransaction::Commit() {
  failed_path_.clear();
  DropRemovalsOfMissingFiles();
  if (planned_.empty()) return {};
  const auto record_path = dir_ / kCommitRecordName;
  // An earlier record still in place would, after a kill during our staging, make recovery roll
  // forward onto our half-staged files: refuse until recovery has settled it.
  std::error_code exists_ec;
  if (fs::symlink_status(record_path, exists_ec).type() != fs::file_type::not_found)
    return Fail(record_path, std::make_error_code(std::errc::device_or_resource_busy));
  if (auto ec = Stage()) return ec;
  const auto record = Record();
  if (auto ec = WriteFileAtomically(record_path, EncodeCommitRecord(record))) return Fail(record_path, ec);
  std::vector<std::string> done;
  if (auto ec = ApplyCommitted(dir_, record, done)) return Fail(dir_, ec);
  if (auto ec = RemoveFileDurably(record_path)) return Fail(record_path, ec);
  return {};
}

std::string TransactionRecovery::ToString() const {
  switch (outcome) {
    case Outcome::kNothing:
      return {};
    case Outcome::kCompleted:
      return "completed an interrupted " + operation + " (" +
             (files.empty() ? std::string("every file was in place already")
                            : "finished " + JoinNames(files)) +
             ")";
    case Outcome::kDiscarded: {
      std::string out = "discarded an unfinished " + (operation.empty() ? std::string("change") : operation) +
                        " (the stored files stay as they were";
      if (!files.empty()) out += "; removed " + JoinNames(files);
      if (!record_problem.empty()) out += "; " + std::string(kCommitRecordName) + ": " + record_problem;
      return out + ")";
    }
  }
  return {};
}

std::error_code RecoverStoreTransaction(const fs::path& dir, TransactionRecovery& out) {
  out = {};
  Bytes bytes;
  const auto ec = ReadWholeFile(dir / kCommitRecordName, kMaxRecordSize, bytes);
  if (IsMissing(ec)) return RollBack(dir, {}, out);
  // Oversized is as undecodable as torn; any other error means the record could not be looked at,
  // and rolling back a change that may be committed would lose it: leave everything for a retry.
  if (ec && ec != std::errc::file_too_large) return ec;
  std::string problem = ec ? "larger than any commit record" : std::string();
  if (!ec) {
    if (auto record = DecodeCommitRecord(bytes, &problem)) return RollForward(dir, *record, out);
  }
  return RollBack(dir, std::move(problem), out);
}

}  // namespace canfleet::canopen
