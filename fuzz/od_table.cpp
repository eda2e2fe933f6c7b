// Fuzzes the dictionary-table reader (node/devices/dictionary/od_table.hpp, FORMAT.md) with
// arbitrary text: any input gives an EdsFile or an OdTableError naming the file and a line within
// the text (another exception escaping is a crash here), never a hang or a runaway allocation
// (an @for loop may not multiply the input without bound). What parses must be an EDS our EDS
// reader takes back: WriteEds -> ParseEds gives the same contents.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "node/canopen/eds/eds_compare.hpp"
#include "node/canopen/eds/eds_reader.hpp"
#include "node/canopen/eds/eds_writer.hpp"
#include "node/devices/dictionary/od_table.hpp"

using namespace canfleet;
using namespace canfleet::canopen;

namespace {

[[noreturn]] void Abort(const char* what, const std::string& detail, std::string_view input) {
  std::fprintf(stderr, "od_table fuzz: %s: %s\n--- input ---\n%.*s\n", what, detail.c_str(),
               static_cast<int>(input.size()), input.data());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  EdsFile table;
  try {
    table = devices::ParseOdTable(text, "fuzz.od");
  } catch (const devices::OdTableError& e) {
    const auto lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
    if (e.file() != "fuzz.od") Abort("an error names another file", e.what(), text);
    if (e.line() > lines) Abort("an error names a line past the end", e.what(), text);
    return 0;
  }
  std::string eds;
  try {
    eds = WriteEdsString(table, EdsFormat::kEds);
  } catch (const EdsError& e) {
    Abort("a table that was read cannot be written as an EDS", e.what(), text);
  }
  EdsFile again;
  try {
    again = ParseEds(eds, "fuzz.eds");
  } catch (const EdsError& e) {
    Abort("the EDS written from a table cannot be read", std::string(e.what()) + "\n" + eds, text);
  }
  const auto diffs = DiffEdsFiles(table, again, EdsFormat::kEds);
  if (!diffs.empty()) Abort("the EDS written from a table reads back differently", diffs.front(), text);
  return 0;
}
