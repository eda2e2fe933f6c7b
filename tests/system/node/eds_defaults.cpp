#include "tests/system/node/eds_defaults.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <set>

#include "tests/system/node/node_system_support.hpp"

namespace canfleet::system_test {

namespace {

using Section = std::map<std::string, std::string>;  // lower-case key -> value

std::string Trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string Upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::toupper(c); });
  return s;
}

bool IsHex(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isxdigit(c); });
}

/// "0x1A", "26", "-3" (CiA 306 §4.6.3: hexadecimal with 0x, else decimal).
std::optional<std::int64_t> ParseNumber(const std::string& text) {
  std::string t = Trim(text);
  if (t.empty()) return std::nullopt;
  try {
    std::size_t used = 0;
    std::int64_t v = 0;
    if (t.size() > 2 && t[0] == '0' && (t[1] == 'x' || t[1] == 'X')) {
      v = static_cast<std::int64_t>(std::stoull(t.substr(2), &used, 16));
      used += 2;
    } else {
      v = std::stoll(t, &used, 10);
    }
    if (used != t.size()) return std::nullopt;
    return v;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

/// A default: a sum of numbers and $NODEID terms ("$NODEID+0x180").
std::optional<std::int64_t> ParseDefault(const std::string& text, std::uint8_t node_id) {
  std::int64_t sum = 0;
  std::size_t start = 0;
  const std::string t = Trim(text);
  for (;;) {
    const auto plus = t.find('+', start);
    const std::string term =
        Trim(t.substr(start, plus == std::string::npos ? std::string::npos : plus - start));
    if (Upper(term) == "$NODEID") {
      sum += node_id;
    } else {
      const auto v = ParseNumber(term);
      if (!v) return std::nullopt;
      sum += *v;
    }
    if (plus == std::string::npos) return sum;
    start = plus + 1;
  }
}

/// Encoded size of the basic types (CiA 301 §7.1.6, table 44); 0 = variable (strings).
std::optional<int> SizeOf(std::uint16_t type) {
  switch (type) {
    case 0x0001:  // BOOLEAN
    case 0x0002:  // INTEGER8
    case 0x0005:  // UNSIGNED8
      return 1;
    case 0x0003:  // INTEGER16
    case 0x0006:  // UNSIGNED16
      return 2;
    case 0x0010:  // INTEGER24
    case 0x0016:  // UNSIGNED24
      return 3;
    case 0x0004:  // INTEGER32
    case 0x0007:  // UNSIGNED32
      return 4;
    case 0x0015:  // INTEGER64
    case 0x001B:  // UNSIGNED64
      return 8;
    case 0x0009:  // VISIBLE_STRING
    case 0x000A:  // OCTET_STRING (written as text here)
      return 0;
    default:
      return std::nullopt;
  }
}

std::string IndexName(std::uint16_t index) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04X", index);
  return buf;
}

}  // namespace

std::string EdsDefault::Label() const {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%04Xh.%u", index, static_cast<unsigned>(sub));
  return std::string(buf) + " " + name;
}

EdsContents ReadEdsDefaults(const std::filesystem::path& path, std::uint8_t node_id) {
  EdsContents out;
  std::ifstream in(path);
  if (!in) {
    out.problems.push_back("cannot open " + path.string());
    return out;
  }
  std::map<std::string, Section> sections;  // upper-case name
  Section* current = nullptr;
  for (std::string raw; std::getline(in, raw);) {
    const std::string line = Trim(raw);
    if (line.empty() || line[0] == ';' || line[0] == '#') continue;
    if (line.front() == '[' && line.back() == ']') {
      current = &sections[Upper(Trim(line.substr(1, line.size() - 2)))];
      continue;
    }
    const auto eq = line.find('=');
    if (current == nullptr || eq == std::string::npos) {
      out.problems.push_back("unexpected line: " + line);
      continue;
    }
    (*current)[Lower(Trim(line.substr(0, eq)))] = Trim(line.substr(eq + 1));
  }

  // The object lists (CiA 306 §4.6.1): every listed object has a section, and every object
  // section is listed.
  std::set<std::uint16_t> listed;
  for (const char* list : {"MANDATORYOBJECTS", "OPTIONALOBJECTS", "MANUFACTUREROBJECTS"}) {
    const auto it = sections.find(list);
    if (it == sections.end()) continue;
    const auto count = ParseNumber(it->second["supportedobjects"]).value_or(0);
    for (std::int64_t i = 1; i <= count; ++i) {
      const auto index = ParseNumber(it->second[std::to_string(i)]);
      if (!index) {
        out.problems.push_back(std::string(list) + " entry " + std::to_string(i) + " missing");
        continue;
      }
      listed.insert(static_cast<std::uint16_t>(*index));
    }
  }

  auto entry_from = [&](const Section& s, std::uint16_t index, std::uint8_t sub) {
    EdsDefault e;
    e.index = index;
    e.sub = sub;
    const auto get = [&](const char* key) {
      const auto it = s.find(key);
      return it == s.end() ? std::string() : it->second;
    };
    e.name = get("parametername");
    e.data_type = static_cast<std::uint16_t>(ParseNumber(get("datatype")).value_or(0));
    e.access = Lower(get("accesstype"));
    e.default_text = get("defaultvalue");
    const auto size = SizeOf(e.data_type);
    if (!size) {
      out.problems.push_back(e.Label() + ": data type " + get("datatype") + " not handled by this reader");
    } else if (*size == 0) {
      e.value.assign(e.default_text.begin(), e.default_text.end());
    } else {
      // CiA 306 §4.6.3.2: a missing or empty DefaultValue is 0.
      const auto v =
          e.default_text.empty() ? std::optional<std::int64_t>(0) : ParseDefault(e.default_text, node_id);
      if (!v)
        out.problems.push_back(e.Label() + ": DefaultValue '" + e.default_text + "' not understood");
      else
        e.value = Le(static_cast<std::uint64_t>(*v), *size);
    }
    out.entries.push_back(std::move(e));
  };

  for (const auto& [name, section] : sections) {
    if (name.size() != 4 || !IsHex(name)) continue;
    const auto index = static_cast<std::uint16_t>(std::stoul(name, nullptr, 16));
    if (!listed.contains(index))
      out.problems.push_back("object " + name + " has a section but is in no object list");
    const auto type_it = section.find("objecttype");
    const auto object_type = type_it == section.end() ? 7 : ParseNumber(type_it->second).value_or(7);
    if (object_type == 7) {
      entry_from(section, index, 0);
      continue;
    }
    const std::string prefix = name + "SUB";
    for (const auto& [sub_name, sub_section] : sections) {
      if (!sub_name.starts_with(prefix) || !IsHex(sub_name.substr(prefix.size()))) continue;
      entry_from(sub_section, index,
                 static_cast<std::uint8_t>(std::stoul(sub_name.substr(prefix.size()), nullptr, 16)));
    }
  }
  for (std::uint16_t index : listed)
    if (!sections.contains(IndexName(index)))
      out.problems.push_back("object " + IndexName(index) + " listed without a section");
  std::sort(out.entries.begin(), out.entries.end(), [](const EdsDefault& a, const EdsDefault& b) {
    return std::pair(a.index, a.sub) < std::pair(b.index, b.sub);
  });
  return out;
}

EdsComparison CompareWithEds(BusMaster& master, std::uint8_t node_id, const EdsContents& eds) {
  EdsComparison result;
  for (const EdsDefault& e : eds.entries) {
    const BusMaster::Upload got = master.Read(node_id, e.index, e.sub);
    std::optional<canopen::SdoAbort> expected_abort;
    if (!e.readable()) expected_abort = canopen::SdoAbort::kWriteOnly;
    if (e.index == 0x1003 && e.sub > 0) expected_abort = canopen::SdoAbort::kNoData;
    if (expected_abort) {
      ++result.refused;
      if (got.abort != *expected_abort)
        result.mismatches.push_back(
            e.Label() + ": expected abort " + AbortText(*expected_abort) + ", got " +
            (got.abort == canopen::SdoAbort::kNone ? HexBytes(got.data) : AbortText(got.abort)));
      continue;
    }
    ++result.compared;
    if (got.abort != canopen::SdoAbort::kNone) {
      result.mismatches.push_back(e.Label() + ": EDS default " + e.default_text + ", read aborted " +
                                  AbortText(got.abort));
    } else if (got.data.size() != e.value.size()) {
      result.mismatches.push_back(e.Label() + ": EDS default " + e.default_text + " is " +
                                  std::to_string(e.value.size()) + " byte(s) (" + HexBytes(e.value) +
                                  "), the node sent " + std::to_string(got.data.size()) + " (" +
                                  HexBytes(got.data) + ")");
    } else if (got.data != e.value) {
      result.mismatches.push_back(e.Label() + ": EDS default " + e.default_text + " (" + HexBytes(e.value) +
                                  "), the node sent " + HexBytes(got.data));
    }
  }
  return result;
}

}  // namespace canfleet::system_test
