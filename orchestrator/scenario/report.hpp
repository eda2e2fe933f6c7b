#pragma once
/// @file What `canfleet test` reports (issue 21): one line per expectation as it is decided, a
/// summary line, and JUnit XML (one test suite per scenario file, one test case per expectation;
/// a failure's message names what was seen instead and when), the format CI servers read.

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "orchestrator/scenario/scenario_runner.hpp"

namespace canfleet::scenario {

/// One scenario file's run.
struct FileReport {
  std::string file;      ///< as given on the command line
  std::string topology;  ///< its name
  std::vector<Result> results;
  std::vector<int> lines;  ///< the line of each result's step (0: unknown), parallel to results
  /// The run could not judge the file (refused, the fleet did not start): every expectation
  /// not decided is then skipped, and the suite has an error.
  std::string error;
  TimePoint origin{};  ///< the scenario's start, for times in messages
  double seconds = 0;  ///< the whole run, start of the fleet to its stop (simulated in virtual time)
  double factor = 0;   ///< virtual time: simulated seconds per real second achieved; 0 in real time
};

/// Totals over results (pending ones count as skipped).
struct Totals {
  std::size_t tests = 0, passed = 0, failed = 0, skipped = 0, errors = 0;
  void Add(const FileReport& file);
  bool AllPassed() const { return tests > 0 && passed == tests && errors == 0; }
};

/// "pass  heartbeat-loss.textproto:31  cut-emcy: EMCY 8130h from quad-6 within 1500 ms after cut-hb:
/// seen EMCY 8130h (register 11h, data 05 08 00 00 00) at t=5.412 s".
std::string ResultLine(const std::string& file, int line, const Result& result);
/// "canfleet test: 17 passed, 1 failed, 0 skipped, 0 errors (18 expectations in 2 files, 23.4 s)".
std::string SummaryLine(const Totals& totals, std::size_t files, double seconds);

struct JunitRun {
  std::vector<FileReport> files;
  std::optional<std::uint64_t> seed;
  std::string time_mode = "real";
};

/// The JUnit XML document (the testsuites/testsuite/testcase schema Jenkins and GitLab read).
void WriteJunit(std::ostream& out, const JunitRun& run);

/// `text` escaped for XML attributes and text.
std::string XmlEscape(const std::string& text);

}  // namespace canfleet::scenario
