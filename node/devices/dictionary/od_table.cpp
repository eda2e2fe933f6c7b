#include "node/devices/dictionary/od_table.hpp"

#include <array>
#include <charconv>
#include <fstream>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "node/canopen/eds/eds_number.hpp"
#include "node/canopen/eds/eds_value.hpp"
#include "node/canopen/od/types.hpp"
#include "node/devices/dictionary/table_facts.hpp"
#include "node/devices/dictionary/table_lines.hpp"

namespace canfleet::devices {
namespace {

using canopen::DataType;
using canopen::EdsFile;
using canopen::Object;
using canopen::ObjectCode;
using canopen::SubObject;
using od_table::TableLine;
using od_table::Trim;

enum Column : std::size_t {
  kIndex,
  kKind,
  kName,
  kType,
  kAccess,
  kPdo,
  kDefault,
  kLow,
  kHigh,
  kManual,
  kColumns
};
constexpr std::array<std::string_view, kColumns> kColumnNames = {
    "index", "kind", "name", "type", "access", "pdo", "default", "low", "high", "manual"};

/// The row being read, for located errors.
struct Row {
  std::string_view file;
  std::size_t line;
  std::vector<std::string_view> cells;

  [[noreturn]] void Fail(Column column, const std::string& detail) const {
    throw OdTableError(std::string(file), line, std::string(kColumnNames[column]), detail);
  }
  std::string_view operator[](Column column) const { return cells[column]; }
};

std::vector<std::string_view> SplitCells(std::string_view text) {
  if (text.starts_with('|')) text.remove_prefix(1);
  if (text.ends_with('|')) text.remove_suffix(1);
  std::vector<std::string_view> cells;
  while (true) {
    auto bar = text.find('|');
    cells.push_back(Trim(text.substr(0, bar)));
    if (bar == std::string_view::npos) break;
    text.remove_prefix(bar + 1);
  }
  return cells;
}

bool IsHeaderOrRule(const std::vector<std::string_view>& cells) {
  if (cells.front() == "index") return true;
  return cells.front().find_first_not_of("-: ") == std::string_view::npos;
}

std::optional<unsigned> Decimal(std::string_view text) {
  unsigned value = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

std::uint16_t ParseIndex(const Row& row) {
  std::string_view text = row[kIndex];
  if (text.ends_with('h') || text.ends_with('H')) text.remove_suffix(1);
  std::uint16_t index = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), index, 16);
  if (text.size() != 4 || ec != std::errc() || end != text.data() + text.size() || index == 0)
    row.Fail(kIndex, "\"" + std::string(row[kIndex]) + "\" is not an index of 4 hex digits");
  return index;
}

DataType ParseType(const Row& row) {
  static const std::array<std::pair<std::string_view, DataType>, 10> kShort = {{
      {"BOOL", DataType::kBoolean},
      {"I8", DataType::kInteger8},
      {"I16", DataType::kInteger16},
      {"I32", DataType::kInteger32},
      {"I64", DataType::kInteger64},
      {"U8", DataType::kUnsigned8},
      {"U16", DataType::kUnsigned16},
      {"U32", DataType::kUnsigned32},
      {"U64", DataType::kUnsigned64},
      {"R32", DataType::kReal32},
  }};
  std::string_view text = row[kType];
  for (const auto& [name, type] : kShort) {
    if (text == name) return type;
  }
  for (std::uint16_t code = 1; code <= 0x1B; ++code) {
    auto type = static_cast<DataType>(code);
    if (canopen::IsKnown(type) && canopen::ToString(type) == text) return type;
  }
  row.Fail(kType,
           "\"" + std::string(text) + "\" is not a CiA 301 data type (UNSIGNED8, INTEGER16, REAL32...)");
}

/// A cell's values for `count` sub-objects: one value for all, or a list ("40*7,10000*5").
std::vector<std::string_view> ValueList(const Row& row, Column column, DataType type, std::size_t count) {
  std::string_view text = row[column];
  // A string is one value, commas and stars included.
  const bool one_value = canopen::IsVariableLength(type);
  if (one_value || text.find(',') == std::string_view::npos) {
    std::string_view one = text;
    auto star = one.rfind('*');
    const std::optional<unsigned> repeat =
        one_value || star == std::string_view::npos ? std::nullopt : Decimal(one.substr(star + 1));
    if (repeat.has_value()) {
      const unsigned times = repeat.value();
      if (times != count)
        row.Fail(column, "\"" + std::string(text) + "\" gives " + std::to_string(times) + " values for " +
                             std::to_string(count) + " sub-objects");
      one = one.substr(0, star);
    }
    return std::vector<std::string_view>(count, Trim(one));
  }
  std::vector<std::string_view> values;
  while (true) {
    auto comma = text.find(',');
    std::string_view item = Trim(text.substr(0, comma));
    auto star = item.rfind('*');
    std::optional<unsigned> repeat =
        star == std::string_view::npos ? std::nullopt : Decimal(item.substr(star + 1));
    if (star != std::string_view::npos && !repeat)
      row.Fail(column, "\"" + std::string(item) + "\": a repeat is VALUE*COUNT");
    std::string_view value = repeat ? Trim(item.substr(0, star)) : item;
    for (unsigned k = 0; k < repeat.value_or(1); ++k) {
      if (values.size() == count)
        row.Fail(column, "the list gives more than " + std::to_string(count) + " values");
      values.push_back(value);
    }
    if (comma == std::string_view::npos) break;
    text.remove_prefix(comma + 1);
  }
  if (values.size() != count)
    row.Fail(column, "the list gives " + std::to_string(values.size()) + " values for " +
                         std::to_string(count) + " sub-objects");
  return values;
}

canopen::EdsValue ParseValue(const Row& row, Column column, DataType type, std::string_view text) {
  try {
    return canopen::ParseEdsValue(type, text, true);
  } catch (const canopen::EdsValueError& e) {
    row.Fail(column, e.what());
  }
}

/// The sub-index run of a sub-object row: "3" or "1..12".
std::pair<unsigned, unsigned> ParseSubRun(const Row& row) {
  std::string_view text = row[kKind];
  auto dots = text.find("..");
  auto first = Decimal(text.substr(0, dots));
  auto last = dots == std::string_view::npos ? first : Decimal(text.substr(dots + 2));
  if (!first || !last || *last < *first || *last > 0xFE)
    row.Fail(kKind,
             "\"" + std::string(text) + "\" is not VAR, ARRAY, RECORD, a sub-index or FIRST..LAST (0..254)");
  return {*first, *last};
}

std::string SubName(std::string_view pattern, unsigned sub, unsigned position) {
  std::string name(pattern);
  for (auto [token, value] :
       {std::pair{std::string_view("{n}"), sub}, std::pair{std::string_view("{i}"), position}}) {
    for (auto at = name.find(token); at != std::string::npos; at = name.find(token))
      name.replace(at, token.size(), std::to_string(value));
  }
  return name;
}

class TableReader {
 public:
  TableReader(std::string_view file) : file_(file) {}

  EdsFile Read(std::string_view text) {
    for (const TableLine& line : od_table::ExpandLines(text, file_)) {
      if (line.text.front() == '@') {
        od_table::ApplyFact(std::string_view(line.text).substr(1), file_, line.number, out_, facts_);
      } else if (line.text.front() == '|') {
        ReadRow(line);
      } else {
        throw OdTableError(std::string(file_), line.number, "",
                           "a line is a row (|...|), a fact (@key value), @for/@end or a # comment");
      }
    }
    Finish();
    return std::move(out_);
  }

 private:
  void ReadRow(const TableLine& line) {
    Row row{file_, line.number, SplitCells(line.text)};
    if (IsHeaderOrRule(row.cells)) return;
    if (row.cells.size() != kColumns) {
      throw OdTableError(std::string(file_), line.number, "",
                         "a row has " + std::to_string(kColumns) +
                             " cells (index | kind | name | type | access | pdo | "
                             "default | low | high | manual), this one " +
                             std::to_string(row.cells.size()));
    }
    std::uint16_t index = ParseIndex(row);
    std::string_view kind = row[kKind];
    if (kind == "VAR" || kind == "ARRAY" || kind == "RECORD") {
      ReadObject(row, index, kind);
    } else {
      ReadSubObjects(row, index);
    }
  }

  void ReadObject(const Row& row, std::uint16_t index, std::string_view kind) {
    if (out_.od.Find(index)) row.Fail(kIndex, "object " + Hex(index) + "h is defined twice");
    if (row[kName].empty()) row.Fail(kName, "an object needs a name");
    if (row[kManual].empty()) row.Fail(kManual, "an object row cites its manual section");
    Object object;
    object.index = index;
    object.name = std::string(row[kName]);
    object.code = kind == "VAR"     ? ObjectCode::kVar
                  : kind == "ARRAY" ? ObjectCode::kArray
                                    : ObjectCode::kRecord;
    if (object.code != ObjectCode::kVar) {
      for (Column c : {kType, kAccess, kPdo, kDefault, kLow, kHigh}) {
        if (!row[c].empty())
          row.Fail(c, "an ARRAY or RECORD row leaves this cell empty: its sub-objects carry it");
      }
      out_.od.Add(std::move(object));
      lines_[index] = row.line;
      return;
    }
    SubObject var = MakeSub(row, index, 0, row[kName], 1, 0, 0);
    var.name = object.name;  // a VAR has one ParameterName (CiA 306 §4.5.2): {n} is for runs only
    object.subs.emplace(0, std::move(var));
    out_.od.Add(std::move(object));
    lines_[index] = row.line;
  }

  void ReadSubObjects(const Row& row, std::uint16_t index) {
    Object* object = out_.od.Find(index);
    if (!object) row.Fail(kIndex, "sub-objects of " + Hex(index) + "h come after its ARRAY or RECORD row");
    if (object->code == ObjectCode::kVar)
      row.Fail(kKind, Hex(index) + "h is a VAR: it has no further sub-objects");
    auto [first, last] = ParseSubRun(row);
    std::size_t count = last - first + 1;
    DataType type = ParseType(row);
    for (unsigned sub = first; sub <= last; ++sub) {
      if (object->subs.contains(static_cast<std::uint8_t>(sub)))
        row.Fail(kKind, "sub-index " + std::to_string(sub) + " of " + Hex(index) + "h is defined twice");
      SubObject made = MakeSub(row, index, sub, row[kName], sub - first + 1, sub - first, count, type);
      made.index = index;
      object->subs.emplace(static_cast<std::uint8_t>(sub), std::move(made));
    }
  }

  /// One sub-object of a row: value `position` (0-based) of lists of `count` values.
  SubObject MakeSub(const Row& row, std::uint16_t index, unsigned sub, std::string_view name,
                    unsigned ordinal, std::size_t position, std::size_t count,
                    std::optional<DataType> known_type = std::nullopt) {
    DataType type = known_type ? *known_type : ParseType(row);
    auto access = canopen::ParseAccess(row[kAccess]);
    if (!access)
      row.Fail(kAccess, "\"" + std::string(row[kAccess]) + "\" is not ro, wo, rw, rwr, rww or const");
    if (row[kPdo] != "0" && row[kPdo] != "1")
      row.Fail(kPdo, "\"" + std::string(row[kPdo]) + "\" is not 0 or 1");
    std::size_t n = count == 0 ? 1 : count;
    std::size_t at = count == 0 ? 0 : position;
    if (row[kDefault].empty() && !canopen::IsVariableLength(type)) row.Fail(kDefault, "a default is needed");
    canopen::EdsValue value = ParseValue(row, kDefault, type, ValueList(row, kDefault, type, n)[at]);
    SubObject made =
        canopen::MakeSubObject(SubName(name, sub, ordinal), type, *access, value.bytes, row[kPdo] == "1");
    made.sub_index = static_cast<std::uint8_t>(sub);
    made.default_adds_node_id = value.adds_node_id;
    for (auto [column, limit] :
         {std::pair{kLow, &SubObject::low_limit}, std::pair{kHigh, &SubObject::high_limit}}) {
      if (row[column].empty()) continue;
      // As in CiA 306 (and our EDS reader, which ignores them in a foreign file): limits bound
      // numbers. In our own table one on a string is a mistake, and it would not survive the EDS.
      if (canopen::IsVariableLength(type)) {
        row.Fail(column, "a limit bounds a number; " + std::string(canopen::ToString(type)) + " has none");
      }
      canopen::EdsValue bound = ParseValue(row, column, type, ValueList(row, column, type, n)[at]);
      made.*limit = bound.bytes;
      if (bound.adds_node_id) {
        auto& flags = out_.node_id_limits[{index, static_cast<std::uint8_t>(sub)}];
        (column == kLow ? flags.low : flags.high) = true;
      }
    }
    return made;
  }

  /// Whole-table checks: every ARRAY/RECORD has sub 0 equal to its highest sub-index; PDO counts.
  void Finish() {
    std::uint16_t rx = 0;
    std::uint16_t tx = 0;
    for (const auto& [index, object] : out_.od.objects()) {
      if (index >= 0x1400 && index <= 0x15FF) ++rx;
      if (index >= 0x1800 && index <= 0x19FF) ++tx;
      if (object.code == ObjectCode::kVar) continue;
      const auto at = index;  // clang 14 cannot capture a structured binding
      auto fail = [&](const std::string& detail) {
        throw OdTableError(std::string(file_), lines_[at], "kind", Hex(at) + "h " + detail);
      };
      auto sub0 = object.subs.find(0);
      if (sub0 == object.subs.end()) fail("has no sub-index 0");
      if (sub0->second.type != DataType::kUnsigned8) fail("sub-index 0 is not UNSIGNED8");
      unsigned highest = object.subs.rbegin()->first;
      if (sub0->second.default_value.size() == 1 && sub0->second.default_value[0] != highest &&
          sub0->second.access == canopen::Access::kRo && object.code == ObjectCode::kArray) {
        fail("sub-index 0 says " + std::to_string(sub0->second.default_value[0]) +
             " but the highest sub-index is " + std::to_string(highest));
      }
    }
    if (!facts_.nr_of_rx_pdo) out_.device_info.nr_of_rx_pdo = rx;
    if (!facts_.nr_of_tx_pdo) out_.device_info.nr_of_tx_pdo = tx;
    if (out_.od.objects().empty()) throw OdTableError(std::string(file_), 0, "", "the table has no objects");
  }

  static std::string Hex(std::uint16_t index) {
    static constexpr char kDigits[] = "0123456789ABCDEF";
    std::string text(4, '0');
    for (int i = 3; i >= 0; --i, index = static_cast<std::uint16_t>(index >> 4))
      text[static_cast<std::size_t>(i)] = kDigits[index & 0xF];
    return text;
  }

  std::string_view file_;
  EdsFile out_;
  od_table::FactsSeen facts_;
  std::map<std::uint16_t, std::size_t> lines_;
};

}  // namespace

OdTableError::OdTableError(std::string file, std::size_t line, std::string column, std::string detail)
    : std::runtime_error(file + ":" + std::to_string(line) + ": " +
                         (column.empty() ? "" : "column \"" + column + "\": ") + detail),
      file_(std::move(file)),
      line_(line),
      column_(std::move(column)),
      detail_(std::move(detail)) {}

canopen::EdsFile ParseOdTable(std::string_view text, std::string_view file_name) {
  return TableReader(file_name).Read(text);
}

canopen::EdsFile ReadOdTable(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw OdTableError(path.string(), 0, "", "cannot open the file");
  std::ostringstream text;
  text << in.rdbuf();
  return ParseOdTable(text.str(), path.filename().string());
}

}  // namespace canfleet::devices
