// 1010h/1011h sub 1 (save all, restore all) as one transaction (store_transaction.hpp): after a
// kill at any moment every group comes from the same save. The crash-point tests build the state
// each step of StoreTransaction::Commit leaves by writing the files directly; the kill tests kill a
// process that saves in a loop and check what the next start loads.
#include "node/canopen/storage/store_transaction.hpp"

#include <gtest/gtest.h>

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <random>
#include <thread>

#include "node/canopen/storage/atomic_file.hpp"
#include "node/canopen/storage/parameter_store.hpp"

namespace canfleet::canopen {
namespace {

namespace fs = std::filesystem;
using Outcome = TransactionRecovery::Outcome;

constexpr std::uint8_t kNodeId = 5;
/// One object per group, each holding the "generation" of the save that wrote it: a load whose
/// three values differ mixes groups from different saves.
constexpr std::array<std::uint16_t, 3> kGenerationObjects{
    0x1017,  // communication: producer heartbeat time
    0x2001,  // manufacturer
    0x6001,  // application
};

void BuildDictionary(ObjectDictionary& od) {
  AddStorageObjects(od);
  Object identity;
  identity.index = 0x1018;
  identity.code = ObjectCode::kRecord;
  for (std::uint8_t sub = 0; sub <= 2; ++sub) {
    SubObject s;
    s.type = sub == 0 ? DataType::kUnsigned8 : DataType::kUnsigned32;
    s.access = Access::kRo;
    s.default_value = sub == 0 ? Bytes{2} : EncodeLe<std::uint32_t>(sub == 1 ? 0x55 : 0xAA020411);
    identity.subs.emplace(sub, std::move(s));
  }
  od.Add(std::move(identity));
  od.AddVar(0x1017, "Producer heartbeat time", DataType::kUnsigned16, Access::kRw,
            EncodeLe<std::uint16_t>(0));
  od.AddVar(0x2001, "Manufacturer generation", DataType::kUnsigned16, Access::kRw,
            EncodeLe<std::uint16_t>(0));
  od.AddVar(0x6001, "Application generation", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(0));
}

/// A node brought up on a state directory like the stack does at reset node: dictionary,
/// store (which settles an interrupted transaction), defaults, stored values.
struct Node {
  explicit Node(const fs::path& dir) {
    BuildDictionary(od);
    store = std::make_unique<ParameterStore>(od, dir);
    od.RestoreDefaults(0x1000, 0xFFFF, kNodeId);
    report = store->ApplyStored(0x1000, 0xFFFF, kNodeId);
  }
  void SetGeneration(std::uint16_t generation) {
    for (auto index : kGenerationObjects)
      od.Write(index, 0, EncodeLe<std::uint16_t>(generation), Origin::kDevice);
  }
  std::array<std::uint64_t, 3> Generations() const {
    return {od.GetUnsigned(kGenerationObjects[0], 0), od.GetUnsigned(kGenerationObjects[1], 0),
            od.GetUnsigned(kGenerationObjects[2], 0)};
  }

  ObjectDictionary od;
  std::unique_ptr<ParameterStore> store;
  LoadReport report;
};

std::array<std::uint64_t, 3> AllGenerations(std::uint64_t generation) {
  return {generation, generation, generation};
}

void WriteRaw(const fs::path& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

Bytes ReadRaw(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

/// Staged files and commit records: what a transaction leaves behind before it is settled.
std::vector<std::string> Leftovers(const fs::path& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const auto name = entry.path().filename().string();
    if (name.ends_with(kStagedSuffix) || name.starts_with(kCommitRecordName)) out.push_back(name);
  }
  return out;
}

/// The commit record SaveAll writes.
CommitRecord SaveAllRecord() {
  CommitRecord record{"save all", {}};
  for (const auto& group : ParameterGroups())
    record.actions.push_back({FileAction::kReplace, group.file_name});
  return record;
}

/// A state directory of the running test's own.
fs::path TestDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = std::string(info->test_suite_name()) + "-" + info->name();
  for (auto& c : name) {
    if (c == '/') c = '_';
  }
  return fs::path(::testing::TempDir()) / "canfleet-store-transaction" /
         (name + "-" + std::to_string(::getpid()));
}

// ---- The commit record's format

TEST(CommitRecordTest, RoundTrips) {
  CommitRecord record{"restore all",
                      {{FileAction::kRemove, "params-comm.bin"}, {FileAction::kReplace, "params-app.bin"}}};
  const Bytes bytes = EncodeCommitRecord(record);
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 4), "CFTX");
  std::string why;
  auto decoded = DecodeCommitRecord(bytes, &why);
  ASSERT_TRUE(decoded.has_value()) << why;
  EXPECT_EQ(*decoded, record);
}

// A record cut short anywhere (a torn write on a file system that does not rename atomically) is
// never taken for a commit.
TEST(CommitRecordTest, EveryTruncationIsRejected) {
  const Bytes bytes = EncodeCommitRecord(SaveAllRecord());
  for (std::size_t size = 0; size < bytes.size(); ++size) {
    std::string why;
    EXPECT_FALSE(DecodeCommitRecord(std::span(bytes).first(size), &why).has_value()) << size;
    EXPECT_FALSE(why.empty());
  }
}

TEST(CommitRecordTest, EveryFlippedByteIsRejected) {
  const Bytes good = EncodeCommitRecord(SaveAllRecord());
  for (std::size_t i = 0; i < good.size(); ++i) {
    Bytes bad = good;
    bad[i] ^= 0x5A;
    EXPECT_FALSE(DecodeCommitRecord(bad).has_value()) << "byte " << i;
  }
  Bytes longer = good;
  longer.push_back(0);
  EXPECT_FALSE(DecodeCommitRecord(longer).has_value());
}

// Even with a correct CRC a record cannot send recovery outside its directory.
TEST(CommitRecordTest, NamesOutsideTheDirectoryAreRejected) {
  for (const char* name : {"../params-comm.bin", "sub/params-comm.bin", "", ".", "..", "/etc/passwd"}) {
    const Bytes bytes = EncodeCommitRecord({"save all", {{FileAction::kReplace, name}}});
    std::string why;
    EXPECT_FALSE(DecodeCommitRecord(bytes, &why).has_value()) << name;
    EXPECT_NE(why.find("plain file"), std::string::npos) << why;
  }
}

// ---- Recovery from every crash point of a save all

enum class Record : std::uint8_t { kNone, kValid, kTorn, kCorrupt };
constexpr unsigned kComm = 1, kMfr = 2, kApp = 4, kAll = kComm | kMfr | kApp;

/// The state a kill leaves at one point of StoreTransaction::Commit.
struct CrashPoint {
  const char* name;
  unsigned staged;        ///< groups whose "<file>.new" holds the new content
  bool last_staged_torn;  ///< the last staged file is cut in half (killed while writing it)
  Record record;
  unsigned renamed;  ///< groups whose file already holds the new content (no ".new" left)
  bool expect_new;   ///< the groups load from the new save (else from the old one)
  Outcome expect_outcome;
};

class SaveAllCrashTest : public ::testing::TestWithParam<CrashPoint> {
 protected:
  static constexpr std::uint16_t kOld = 1;
  static constexpr std::uint16_t kNew = 2;

  void SetUp() override {
    dir_ = TestDir();
    fs::remove_all(dir_);
    // The new files come from a real save all of generation 2 elsewhere; the old ones from a real
    // save all of generation 1 here.
    {
      Node scratch(dir_ / "new");
      scratch.SetGeneration(kNew);
      ASSERT_EQ(scratch.store->Save(1), SdoAbort::kNone);
    }
    for (const auto& group : ParameterGroups())
      new_content_.push_back(ReadRaw(dir_ / "new" / group.file_name));
    fs::remove_all(dir_ / "new");
    Node node(dir_);
    node.SetGeneration(kOld);
    ASSERT_EQ(node.store->Save(1), SdoAbort::kNone);
  }
  void TearDown() override { fs::remove_all(dir_); }

  void BuildCrashState(const CrashPoint& point) {
    const auto& groups = ParameterGroups();
    fs::path last_staged;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const auto file = dir_ / groups[g].file_name;
      if (point.renamed & (1u << g)) {
        WriteRaw(file, new_content_[g]);
      } else if (point.staged & (1u << g)) {
        last_staged = StagedPathFor(file);
        WriteRaw(last_staged, new_content_[g]);
      }
    }
    if (point.last_staged_torn) {
      Bytes half = ReadRaw(last_staged);
      half.resize(half.size() / 2);
      WriteRaw(last_staged, half);
    }
    Bytes record = EncodeCommitRecord(SaveAllRecord());
    if (point.record == Record::kTorn) record.resize(record.size() - 7);
    if (point.record == Record::kCorrupt) record[record.size() - 3] ^= 0x20;
    if (point.record != Record::kNone) WriteRaw(dir_ / kCommitRecordName, record);
  }

  fs::path dir_;
  std::vector<Bytes> new_content_;  ///< per group, in ParameterGroups() order
};

TEST_P(SaveAllCrashTest, LoadsEveryGroupFromTheSameSave) {
  const CrashPoint& point = GetParam();
  BuildCrashState(point);

  Node node(dir_);
  EXPECT_EQ(node.Generations(), AllGenerations(point.expect_new ? kNew : kOld));
  EXPECT_TRUE(node.report.Clean()) << node.report.ToString();
  EXPECT_EQ(node.report.recovery.outcome, point.expect_outcome) << node.report.ToString();
  EXPECT_TRUE(Leftovers(dir_).empty());
  const std::string log = node.report.ToString();
  const char* expected_line =
      point.expect_outcome == Outcome::kCompleted   ? "completed an interrupted save all"
      : point.expect_outcome == Outcome::kDiscarded ? "discarded an unfinished save all"
                                                    : "";
  EXPECT_NE(log.find(expected_line), std::string::npos) << log;
  EXPECT_EQ(node.report.Quiet(), point.expect_outcome == Outcome::kNothing) << log;

  // Reported once; a second start finds nothing left to do and loads the same (idempotent).
  EXPECT_TRUE(node.store->ApplyStored(0x1000, 0xFFFF, kNodeId).Quiet());
  Node again(dir_);
  EXPECT_TRUE(again.report.Quiet()) << again.report.ToString();
  EXPECT_EQ(again.Generations(), node.Generations());
}

// In the order StoreTransaction::Commit passes them.
INSTANTIATE_TEST_SUITE_P(
    Steps, SaveAllCrashTest,
    ::testing::Values(
        CrashPoint{"NothingStarted", 0, false, Record::kNone, 0, false, Outcome::kNothing},
        CrashPoint{"StagingFirstFile", kComm, true, Record::kNone, 0, false, Outcome::kDiscarded},
        CrashPoint{"StagedSome", kComm | kMfr, false, Record::kNone, 0, false, Outcome::kDiscarded},
        CrashPoint{"StagedAll", kAll, false, Record::kNone, 0, false, Outcome::kDiscarded},
        CrashPoint{"RecordTorn", kAll, false, Record::kTorn, 0, false, Outcome::kDiscarded},
        CrashPoint{"RecordCorrupt", kAll, false, Record::kCorrupt, 0, false, Outcome::kDiscarded},
        CrashPoint{"CommittedNoneRenamed", kAll, false, Record::kValid, 0, true, Outcome::kCompleted},
        CrashPoint{"CommittedCommRenamed", kAll, false, Record::kValid, kComm, true, Outcome::kCompleted},
        CrashPoint{"CommittedTwoRenamed", kAll, false, Record::kValid, kComm | kMfr, true,
                   Outcome::kCompleted},
        CrashPoint{"CommittedAllRenamed", kAll, false, Record::kValid, kAll, true, Outcome::kCompleted},
        CrashPoint{"RecordRemoved", kAll, false, Record::kNone, kAll, true, Outcome::kNothing}),
    [](const ::testing::TestParamInfo<CrashPoint>& param_info) {
      return std::string(param_info.param.name);
    });

// ---- Restore all, failures, and single groups after an interrupted save all

class StoreTransactionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = TestDir();
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Saves all groups with `generation`.
  void SaveAll(std::uint16_t generation) {
    Node node(dir_);
    node.SetGeneration(generation);
    ASSERT_EQ(node.store->Save(1), SdoAbort::kNone) << node.store->LastError();
  }

  fs::path dir_;
};

TEST_F(StoreTransactionTest, SaveAllLeavesNoJournalBehind) {
  SaveAll(7);
  EXPECT_TRUE(Leftovers(dir_).empty());
  Node node(dir_);
  EXPECT_EQ(node.Generations(), AllGenerations(7));
  EXPECT_TRUE(node.report.Quiet());
}

// 1011h sub 1 killed after its record and the first removal: the next start removes the rest.
TEST_F(StoreTransactionTest, InterruptedRestoreAllIsCompleted) {
  SaveAll(3);
  WriteRaw(dir_ / kCommitRecordName, EncodeCommitRecord({"restore all",
                                                         {{FileAction::kRemove, "params-comm.bin"},
                                                          {FileAction::kRemove, "params-mfr.bin"},
                                                          {FileAction::kRemove, "params-app.bin"}}}));
  fs::remove(dir_ / "params-comm.bin");
  Node node(dir_);
  EXPECT_EQ(node.Generations(), AllGenerations(0));  // defaults everywhere
  EXPECT_EQ(node.report.recovery.outcome, Outcome::kCompleted);
  EXPECT_NE(node.report.ToString().find("completed an interrupted restore all"), std::string::npos)
      << node.report.ToString();
  EXPECT_EQ(node.report.recovery.files, (std::vector<std::string>{"params-mfr.bin", "params-app.bin"}));
  EXPECT_TRUE(node.report.files_applied.empty());
  EXPECT_TRUE(Leftovers(dir_).empty());
}

TEST_F(StoreTransactionTest, RestoreAllWithATornRecordKeepsEveryGroup) {
  SaveAll(3);
  Bytes record = EncodeCommitRecord({"restore all", {{FileAction::kRemove, "params-comm.bin"}}});
  record.resize(10);
  WriteRaw(dir_ / kCommitRecordName, record);
  Node node(dir_);
  EXPECT_EQ(node.Generations(), AllGenerations(3));
  EXPECT_EQ(node.report.recovery.outcome, Outcome::kDiscarded);
  EXPECT_NE(node.report.ToString().find("torn"), std::string::npos) << node.report.ToString();
  EXPECT_TRUE(Leftovers(dir_).empty());
}

TEST_F(StoreTransactionTest, RestoreAllRemovesEveryGroupAndWritesNothingWhenNothingIsStored) {
  {
    Node node(dir_);
    ASSERT_EQ(node.store->MarkRestoreDefaults(1), SdoAbort::kNone);
  }
  EXPECT_FALSE(fs::exists(dir_));  // nothing to remove: not even the directory is created
  SaveAll(4);
  {
    Node node(dir_);
    ASSERT_EQ(node.store->MarkRestoreDefaults(1), SdoAbort::kNone);
  }
  EXPECT_TRUE(fs::is_empty(dir_));
}

// Staging fails half-way (here: a directory where the last staged file goes): Save answers
// 06060000h and every group stays as it was.
TEST_F(StoreTransactionTest, FailedSaveAllKeepsEveryGroupOld) {
  SaveAll(1);
  fs::create_directories(StagedPathFor(dir_ / "params-app.bin"));
  {
    Node node(dir_);
    node.SetGeneration(2);
    EXPECT_EQ(node.store->Save(1), SdoAbort::kHardwareError);
    EXPECT_NE(node.store->LastError().find("params-app.bin.new"), std::string::npos)
        << node.store->LastError();
    const auto report = node.store->ApplyStored(0x1000, 0xFFFF, kNodeId);
    EXPECT_EQ(report.recovery.outcome, Outcome::kDiscarded);  // the staged comm and mfr files
  }
  fs::remove(StagedPathFor(dir_ / "params-app.bin"));
  EXPECT_TRUE(Leftovers(dir_).empty());
  Node node(dir_);
  EXPECT_EQ(node.Generations(), AllGenerations(1));
}

// The renames fail after the commit (here: a non-empty directory where params-mfr.bin goes). The
// change is decided but cannot be finished: no further save may write over it until it is, and
// then the finished save all and the later single-group save both count.
TEST_F(StoreTransactionTest, UnfinishedCommitBlocksSavesUntilItCanBeFinished) {
  SaveAll(1);
  Node node(dir_);
  fs::remove(dir_ / "params-mfr.bin");
  fs::create_directories(dir_ / "params-mfr.bin" / "blocker");
  node.SetGeneration(2);
  EXPECT_EQ(node.store->Save(1), SdoAbort::kHardwareError);
  EXPECT_TRUE(fs::exists(dir_ / kCommitRecordName));
  node.SetGeneration(3);
  EXPECT_EQ(node.store->Save(2), SdoAbort::kHardwareError);
  EXPECT_NE(node.store->LastError().find("interrupted"), std::string::npos) << node.store->LastError();
  const auto report = node.store->ApplyStored(0x1000, 0x1FFF, kNodeId);
  ASSERT_EQ(report.issues.size(), 1u) << report.ToString();
  EXPECT_EQ(report.issues[0].file, dir_ / kCommitRecordName);
  EXPECT_EQ(report.issues[0].problem, StoreProblem::kIoError);

  fs::remove_all(dir_ / "params-mfr.bin");
  node.SetGeneration(3);
  EXPECT_EQ(node.store->Save(2), SdoAbort::kNone) << node.store->LastError();
  EXPECT_TRUE(Leftovers(dir_).empty());
  Node after(dir_);
  EXPECT_EQ(after.Generations(), (std::array<std::uint64_t, 3>{3, 2, 2}));
}

// A single-group save after a kill in a save all: the start settles the save all first, so the
// group's own file is not replaced later by a stale staged one.
TEST_F(StoreTransactionTest, SingleGroupSaveAfterAnInterruptedSaveAll) {
  SaveAll(1);
  {
    Node scratch(dir_ / "scratch");
    scratch.SetGeneration(2);
    ASSERT_EQ(scratch.store->Save(1), SdoAbort::kNone);
  }
  for (const auto& group : ParameterGroups())
    fs::rename(dir_ / "scratch" / group.file_name, StagedPathFor(dir_ / group.file_name));
  fs::remove_all(dir_ / "scratch");
  WriteRaw(dir_ / kCommitRecordName, EncodeCommitRecord(SaveAllRecord()));
  {
    Node node(dir_);
    EXPECT_EQ(node.Generations(), AllGenerations(2));
    node.SetGeneration(5);
    ASSERT_EQ(node.store->Save(3), SdoAbort::kNone);
  }
  Node node(dir_);
  EXPECT_EQ(node.Generations(), (std::array<std::uint64_t, 3>{2, 2, 5}));
  EXPECT_TRUE(node.report.Quiet());
}

// ---- Real kills

/// How a child process changes the stored groups in a loop until it is killed.
enum class ChildLoop : std::uint8_t { kSaveAll, kSaveAllAndRestoreAll };

struct KillCounts {
  int kills = 0;
  int mid_transaction = 0;  ///< a staged file or a commit record was left behind
  int completed = 0;
  int discarded = 0;
  int mixed = 0;
};

/// The child: a node on `dir` storing generation after generation, starting at `first`. Never
/// returns; the parent's SIGKILL ends it (or, should the parent die, its death signal or the limit).
[[noreturn]] void RunChild(const fs::path& dir, std::uint16_t first, ChildLoop loop) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  Node node(dir);
  for (std::uint16_t generation = first; std::chrono::steady_clock::now() < give_up; ++generation) {
    node.SetGeneration(generation);
    node.store->Save(1);
    if (loop == ChildLoop::kSaveAllAndRestoreAll && generation % 2 == 0) node.store->MarkRestoreDefaults(1);
  }
  ::_exit(0);
}

/// Microseconds one save all takes here (fsync costs differ widely between machines), for the
/// range of the kill delays; not asserted on.
long MeasureSaveAllMicros(const fs::path& dir) {
  Node node(dir);
  const auto start = std::chrono::steady_clock::now();
  constexpr int kSaves = 5;
  for (int i = 0; i < kSaves; ++i) {
    node.SetGeneration(static_cast<std::uint16_t>(i + 1));
    node.store->Save(1);
  }
  const auto elapsed = std::chrono::steady_clock::now() - start;
  return static_cast<long>(std::chrono::duration_cast<std::chrono::microseconds>(elapsed).count() / kSaves);
}

/// Forks a saving child `kills` times, SIGKILLs it after a random delay, and loads what it left
/// like the next start would.
KillCounts KillWhileSaving(const fs::path& dir, int kills, ChildLoop loop) {
  fs::remove_all(dir);
  const long save_us = std::max(50L, MeasureSaveAllMicros(dir));
  fs::remove_all(dir);
  // Up to three save alls (or save + restore pairs) after the child's start-up, so kills land
  // before the first, inside and between transactions, at every step of them.
  std::mt19937 rng(0xCA9F1EE7);
  std::uniform_int_distribution<long> delay_us(0, 3 * save_us + 200);
  std::printf("[ info     ] one save all takes about %ld us; kill delays 0..%ld us\n", save_us,
              delay_us.max());

  KillCounts counts;
  std::uint64_t last_generation = 0;
  for (int i = 0; i < kills; ++i) {
    const auto first = static_cast<std::uint16_t>(last_generation + 1);
    const pid_t child = ::fork();
    if (child < 0) {
      ADD_FAILURE() << "fork failed";
      break;
    }
    if (child == 0) RunChild(dir, first, loop);
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng)));
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    ++counts.kills;
    if (!Leftovers(dir).empty()) ++counts.mid_transaction;

    Node next_start(dir);
    const auto generations = next_start.Generations();
    if (next_start.report.recovery.outcome == Outcome::kCompleted) ++counts.completed;
    if (next_start.report.recovery.outcome == Outcome::kDiscarded) ++counts.discarded;
    EXPECT_TRUE(next_start.report.Clean()) << "kill " << i << ": " << next_start.report.ToString();
    EXPECT_EQ(Leftovers(dir), std::vector<std::string>{}) << "kill " << i;
    if (generations != AllGenerations(generations[0])) {
      ++counts.mixed;
      ADD_FAILURE() << "kill " << i << ": groups from different saves: comm " << generations[0] << ", mfr "
                    << generations[1] << ", app " << generations[2];
    }
    // A save all that returned is durable: the next start never goes back behind it. (Restores
    // bring generation 0 back on purpose.)
    if (loop == ChildLoop::kSaveAll) {
      EXPECT_GE(generations[0], last_generation) << "kill " << i;
    }
    last_generation = std::max(last_generation, generations[0]);
  }
  std::printf(
      "[ info     ] %d kills, %d mid-transaction (%d completed, %d discarded at the next start), %d mixed\n",
      counts.kills, counts.mid_transaction, counts.completed, counts.discarded, counts.mixed);
  fs::remove_all(dir);
  return counts;
}

// The child loops "set generation n in all three groups, save all"; SIGKILL at a random moment,
// 200 times. Every next start loads all three groups from one save.
TEST(StoreKillTest, SaveAllSurvivesSigkillAtAnyMoment) {
  const auto counts = KillWhileSaving(TestDir(), 200, ChildLoop::kSaveAll);
  EXPECT_EQ(counts.kills, 200);
  EXPECT_EQ(counts.mixed, 0);
  // Otherwise every kill fell between transactions and the test proved nothing.
  EXPECT_GT(counts.mid_transaction, 0);
}

// The same with restore all between the saves: a kill during either leaves all three groups
// stored (from one save) or all three at their defaults.
TEST(StoreKillTest, SaveAllAndRestoreAllSurviveSigkillAtAnyMoment) {
  const auto counts = KillWhileSaving(TestDir(), 60, ChildLoop::kSaveAllAndRestoreAll);
  EXPECT_EQ(counts.mixed, 0);
  EXPECT_GT(counts.mid_transaction, 0);
}

}  // namespace
}  // namespace canfleet::canopen
