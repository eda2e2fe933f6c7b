// Fuzzes the CiA 306 EDS/DCF reader with arbitrary bytes. Any input must give an EdsFile or an
// EdsError (never a crash, hang or runaway allocation), and whatever parses must survive
// WriteEds -> ParseEds as both EDS and DCF with the same contents: a failure there aborts.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "node/canopen/eds/eds_compare.hpp"
#include "node/canopen/eds/eds_reader.hpp"
#include "node/canopen/eds/eds_writer.hpp"

using namespace canfleet::canopen;

namespace {

[[noreturn]] void Abort(const char* what, const std::string& detail, const std::string& text) {
  std::fprintf(stderr, "eds_reader fuzz: %s\n%s\n--- written file ---\n%s\n", what, detail.c_str(),
               text.c_str());
  std::abort();
}

void CheckRoundTrip(const EdsFile& first, EdsFormat format) {
  std::string text;
  try {
    text = WriteEdsString(first, format);
  } catch (const EdsError& e) {
    Abort("a file that was read could not be written", e.what(), "");
  }
  EdsFile second;
  try {
    second = ParseEds(text, format == EdsFormat::kDcf ? "rewritten.dcf" : "rewritten.eds");
  } catch (const EdsError& e) {
    Abort("a written file could not be read back", e.what(), text);
  }
  auto diffs = DiffEdsFiles(first, second, format);
  if (!diffs.empty()) {
    std::string all;
    for (const auto& line : diffs)
      all += line + "\n";
    Abort("the written file reads back differently", all, text);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  EdsFile first;
  try {
    first = ParseEds(text, "fuzz.eds");
  } catch (const EdsError&) {
    return 0;
  }
  CheckRoundTrip(first, EdsFormat::kEds);
  CheckRoundTrip(first, EdsFormat::kDcf);
  return 0;
}
