#include "node/canopen/eds/eds_objects.hpp"

#include <cstdio>
#include <iterator>
#include <optional>
#include <set>
#include <string>

#include "node/canopen/eds/eds_error.hpp"
#include "node/canopen/eds/eds_number.hpp"
#include "node/canopen/eds/eds_value.hpp"
#include "node/canopen/eds/ini_section.hpp"

namespace canfleet::canopen {
namespace {

std::string Hex4(std::uint16_t index) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04X", index);
  return buf;
}

bool IsVarLike(ObjectCode code) {
  return code == ObjectCode::kVar || code == ObjectCode::kDomain || code == ObjectCode::kDefType;
}

/// A decimal key of a list section ("1=0x1000", "3=Name"), or nullopt for other keys.
std::optional<std::uint64_t> DecimalKey(std::string_view key) {
  if (key.empty() || key.size() > 5) return std::nullopt;
  std::uint64_t value = 0;
  for (char c : key) {
    if (c < '0' || c > '9') return std::nullopt;
    value = value * 10 + static_cast<std::uint64_t>(c - '0');
  }
  return value;
}

std::size_t ChargeOf(const SubObject& sub) {
  return sizeof(SubObject) + 64 + sub.name.size() + sub.default_value.size() + sub.value.size() +
         (sub.low_limit ? sub.low_limit->size() : 0) + (sub.high_limit ? sub.high_limit->size() : 0);
}

/// What a dictionary costs against kMaxDictionaryBytes: the structures and their variable parts.
std::size_t DictionaryCharge(const ObjectDictionary& od) {
  std::size_t total = 0;
  for (const auto& [index, obj] : od.objects()) {
    total += sizeof(Object) + obj.name.size();
    for (const auto& [sub_index, sub] : obj.subs)
      total += ChargeOf(sub);
  }
  return total;
}

class ObjectReader {
 public:
  ObjectReader(const EdsSections& sections, std::string_view file_name, EdsFile& out)
      : sections_(sections), file_name_(file_name), out_(out) {}

  void Run() {
    for (const auto& [index, section] : sections_.objects)
      ReadObject(index, *section);
    for (const auto& [key, section] : sections_.subs) {
      if (!out_.od.Find(key.first)) {
        SectionReader(*section, file_name_)
            .FailSection("no object section [" + Hex4(key.first) + "] for this sub-object");
      }
    }
    for (const auto& [index, section] : sections_.names)
      ReadCompactList(index, *section, false);
    for (const auto& [index, section] : sections_.values)
      ReadCompactList(index, *section, true);
    for (const IniSection* list : sections_.object_lists) {
      if (list) ReadObjectList(SectionReader(*list, file_name_));
    }
    // The running charge guards the expansion; this exact count of the finished dictionary is
    // the rule, so that the file WriteEds makes from it reads back under the same bound.
    if (DictionaryCharge(out_.od) > kMaxDictionaryBytes) {
      throw EdsError(
          std::string(file_name_), 0, "", "",
          "object dictionary too large (over " + std::to_string(kMaxDictionaryBytes >> 20) + " MiB)");
    }
  }

 private:
  /// CiA 306 §4.6.3.2 (object description): ParameterName, ObjectType (VAR when absent),
  /// SubNumber or CompactSubObj for ARRAY/RECORD, else the keys of a sub-object.
  void ReadObject(std::uint16_t index, const IniSection& section) {
    SectionReader r(section, file_name_);
    Object obj;
    obj.index = index;
    obj.name = std::string(r.Required("ParameterName"));
    obj.code = ReadObjectType(r, ObjectCode::kVar);
    obj.obj_flags = static_cast<std::uint32_t>(r.Unsigned("ObjFlags", 0xFFFFFFFF).value_or(0));
    Charge(r, sizeof(Object) + obj.name.size());
    const std::uint64_t compact = r.Unsigned("CompactSubObj", 254).value_or(0);
    auto first_sub = sections_.subs.lower_bound({index, 0});
    auto end_sub = sections_.subs.upper_bound({index, 0xFF});

    if (IsVarLike(obj.code)) {
      if (compact != 0)
        r.Fail(r.Find("CompactSubObj"), "CompactSubObj", "only ARRAY and RECORD objects have sub-objects");
      if (first_sub != end_sub) {
        SectionReader(*first_sub->second, file_name_)
            .FailSection("sub-object section for " + std::string(ToString(obj.code)) + " object " +
                         Hex4(index));
      }
      if (auto subs = r.Unsigned("SubNumber", 0xFF); subs && *subs != 0) {
        r.Fail(r.Find("SubNumber"), "SubNumber",
               "a " + std::string(ToString(obj.code)) + " object has no sub-objects");
      }
      SubObject sub = ReadSubObject(r, index, 0, obj.code);
      sub.name = obj.name;
      obj.subs.emplace(0, std::move(sub));
    } else if (compact != 0) {
      if (auto subs = r.Unsigned("SubNumber", 0xFF); subs && *subs != 0) {
        r.Fail(r.Find("SubNumber"), "SubNumber", "not allowed together with CompactSubObj");
      }
      if (first_sub != end_sub) {
        SectionReader(*first_sub->second, file_name_)
            .FailSection("sub-object section for object " + Hex4(index) + ", which has CompactSubObj");
      }
      ExpandCompact(r, obj, static_cast<std::uint8_t>(compact));
    } else {
      const auto count = static_cast<std::uint64_t>(std::distance(first_sub, end_sub));
      auto subs = r.Unsigned("SubNumber", 0xFF);
      if (!subs) r.Fail(nullptr, "SubNumber", "missing for " + std::string(ToString(obj.code)) + " object");
      if (*subs != count) {
        r.Fail(r.Find("SubNumber"), "SubNumber",
               "says " + std::to_string(*subs) + " but " + std::to_string(count) + " sub-object sections [" +
                   Hex4(index) + "subN] exist");
      }
      for (auto it = first_sub; it != end_sub; ++it) {
        SectionReader sub_reader(*it->second, file_name_);
        ObjectCode sub_code = ReadObjectType(sub_reader, ObjectCode::kVar);
        if (!IsVarLike(sub_code)) {
          sub_reader.Fail(sub_reader.Find("ObjectType"), "ObjectType", "a sub-object must be VAR or DOMAIN");
        }
        SubObject sub = ReadSubObject(sub_reader, index, it->first.second, sub_code);
        sub.name = std::string(sub_reader.Required("ParameterName"));
        obj.subs.emplace(it->first.second, std::move(sub));
      }
    }
    if (compact == 0) {
      for (const auto& [sub_index, sub] : obj.subs)
        Charge(r, ChargeOf(sub));
    }
    out_.od.objects().insert_or_assign(index, std::move(obj));
  }

  ObjectCode ReadObjectType(const SectionReader& r, ObjectCode fallback) {
    auto code = r.Unsigned("ObjectType", 0xFF);
    if (!code) return fallback;
    switch (*code) {
      case 0x2:
      case 0x5:
      case 0x6:
      case 0x7:
      case 0x8:
      case 0x9:
        return static_cast<ObjectCode>(*code);
      default: {
        char buf[64];
        std::snprintf(buf, sizeof buf, "0x%X is not an object type (2, 5, 6, 7, 8 or 9)",
                      static_cast<unsigned>(*code));
        r.Fail(r.Find("ObjectType"), "ObjectType", buf);
      }
    }
  }

  /// The keys describing one value (CiA 306 §4.6.3.2): DataType, AccessType, PDOMapping,
  /// LowLimit, HighLimit, DefaultValue, ObjFlags and, in a DCF, ParameterValue (§5).
  SubObject ReadSubObject(const SectionReader& r, std::uint16_t index, std::uint8_t sub_index,
                          ObjectCode code) {
    SubObject sub;
    sub.index = index;
    sub.sub_index = sub_index;
    const bool domain = code == ObjectCode::kDomain;
    if (auto type = r.Unsigned("DataType", 0xFFFF)) {
      sub.type = static_cast<DataType>(*type);
      if (!IsKnown(sub.type)) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "0x%04X is not a supported data type", static_cast<unsigned>(*type));
        r.Fail(r.Find("DataType"), "DataType", buf);
      }
    } else if (domain) {
      sub.type = DataType::kDomain;  // CiA 306: DataType is optional for DOMAIN objects
    } else {
      r.Fail(nullptr, "DataType", "missing");
    }
    if (const IniEntry* entry = r.Find("AccessType"); entry && !entry->value.empty()) {
      auto access = ParseAccess(StripInlineComment(entry->value));
      if (!access) {
        r.Fail(entry, entry->key,
               QuoteForError(entry->value) + " is not an access type (ro, wo, rw, rwr, rww, const)");
      }
      sub.access = *access;
    } else if (domain) {
      sub.access = Access::kRw;
    } else {
      r.Fail(entry, "AccessType", "missing");
    }
    sub.pdo_mappable = r.Flag("PDOMapping").value_or(false);
    sub.obj_flags = static_cast<std::uint32_t>(r.Unsigned("ObjFlags", 0xFFFFFFFF).value_or(0));

    // Limits only mean something for numbers; for strings and domains they are ignored.
    if (!IsVariableLength(sub.type)) {
      NodeIdLimits node_id_limits;
      if (auto low = ParseKey(r, "LowLimit", sub.type)) {
        sub.low_limit = std::move(low->bytes);
        node_id_limits.low = low->adds_node_id;
      }
      if (auto high = ParseKey(r, "HighLimit", sub.type)) {
        sub.high_limit = std::move(high->bytes);
        node_id_limits.high = high->adds_node_id;
      }
      if (node_id_limits != NodeIdLimits{}) out_.node_id_limits[{index, sub_index}] = node_id_limits;
    }

    if (auto def = ParseKey(r, "DefaultValue", sub.type)) {
      sub.default_value = std::move(def->bytes);
      sub.default_adds_node_id = def->adds_node_id;
    } else {
      sub.default_value = Bytes(FixedSize(sub.type).value_or(0), 0);
    }
    sub.value = sub.DefaultFor(out_.dcf_node_id.value_or(0));
    if (auto value = ParseKey(r, "ParameterValue", sub.type)) {
      sub.value = ApplyNodeId(r, r.Find("ParameterValue"), sub.type, *value);
    }
    return sub;
  }

  /// A value key; nullopt when absent, or empty for a number. An empty string or domain is a value.
  std::optional<EdsValue> ParseKey(const SectionReader& r, std::string_view key, DataType type) {
    const IniEntry* entry = r.Find(key);
    if (!entry) return std::nullopt;
    return ParseEntry(r, *entry, type);
  }

  std::optional<EdsValue> ParseEntry(const SectionReader& r, const IniEntry& entry, DataType type) {
    if (StripInlineComment(entry.value).empty() && !IsVariableLength(type)) return std::nullopt;
    try {
      return ParseEdsValue(type, entry.value, true);
    } catch (const EdsValueError& e) {
      r.Fail(&entry, entry.key, e.what());
    }
  }

  /// A current value (DCF ParameterValue, [xxxxValue]) with "$NODEID" resolved: it needs the
  /// DCF's NodeID.
  Bytes ApplyNodeId(const SectionReader& r, const IniEntry* entry, DataType type, const EdsValue& value) {
    if (!value.adds_node_id) return value.bytes;
    if (!out_.dcf_node_id) r.Fail(entry, entry->key, "$NODEID needs [DeviceComissioning] NodeID");
    SubObject scratch;
    scratch.type = type;
    scratch.default_value = value.bytes;
    scratch.default_adds_node_id = true;
    return scratch.DefaultFor(*out_.dcf_node_id);
  }

  /// CiA 306 compact storage: CompactSubObj=n stands for sub0 (the count, UNSIGNED8 ro) and
  /// sub1..n, each described by the object section's own keys and named "<ParameterName><i>".
  void ExpandCompact(const SectionReader& r, Object& obj, std::uint8_t count) {
    obj.compact_sub_obj = count;
    SubObject count_sub;
    count_sub.index = obj.index;
    count_sub.name = "NrOfObjects";
    count_sub.type = DataType::kUnsigned8;
    count_sub.access = Access::kRo;
    count_sub.default_value = {count};
    count_sub.value = {count};
    Charge(r, ChargeOf(count_sub));
    obj.subs.emplace(0, std::move(count_sub));
    SubObject pattern = ReadSubObject(r, obj.index, 1, ObjectCode::kVar);
    NodeIdLimits limits;
    if (auto it = out_.node_id_limits.find({obj.index, 1}); it != out_.node_id_limits.end())
      limits = it->second;
    for (unsigned i = 1; i <= count; ++i) {
      Charge(r, ChargeOf(pattern) + 3);  // before copying: the copies are what could grow
      SubObject sub = pattern;
      sub.sub_index = static_cast<std::uint8_t>(i);
      sub.name = obj.name + std::to_string(i);
      obj.subs.emplace(sub.sub_index, std::move(sub));
      if (limits != NodeIdLimits{}) out_.node_id_limits[{obj.index, static_cast<std::uint8_t>(i)}] = limits;
    }
  }

  /// [xxxxName] / [xxxxValue]: NrOfEntries=m, then "<sub-index>=<name or value>" (decimal keys).
  void ReadCompactList(std::uint16_t index, const IniSection& section, bool values) {
    SectionReader r(section, file_name_);
    Object* obj = out_.od.Find(index);
    if (!obj) r.FailSection("no object section [" + Hex4(index) + "] for this section");
    if (obj->compact_sub_obj == 0) r.FailSection("object " + Hex4(index) + " has no CompactSubObj");
    auto expected = r.Unsigned("NrOfEntries", 0xFF);
    if (!expected) r.Fail(nullptr, "NrOfEntries", "missing");
    std::set<std::uint64_t> seen;
    for (const IniEntry& entry : section.entries) {
      auto sub_index = DecimalKey(entry.key);
      if (!sub_index) continue;
      if (*sub_index < 1 || *sub_index > obj->compact_sub_obj) {
        r.Fail(&entry, entry.key,
               "sub-index " + std::to_string(*sub_index) + " is not in 1.." +
                   std::to_string(obj->compact_sub_obj) + " (CompactSubObj)");
      }
      if (!seen.insert(*sub_index).second) r.Fail(&entry, entry.key, "duplicate key");
      SubObject& sub = obj->subs.at(static_cast<std::uint8_t>(*sub_index));
      if (!values) {
        sub.name = std::string(entry.value);
        continue;
      }
      auto value = ParseEntry(r, entry, sub.type);
      if (!value) r.Fail(&entry, entry.key, "empty value");
      sub.value = ApplyNodeId(r, &entry, sub.type, *value);
    }
    if (seen.size() != *expected) {
      r.Fail(r.Find("NrOfEntries"), "NrOfEntries",
             "says " + std::to_string(*expected) + " but " + std::to_string(seen.size()) + " entries follow");
    }
  }

  /// CiA 306 §4.6.1 object lists: SupportedObjects=n, then 1=0x1000 ... n=0x....
  void ReadObjectList(const SectionReader& r) {
    auto expected = r.Unsigned("SupportedObjects", 0xFFFF);
    if (!expected) r.Fail(nullptr, "SupportedObjects", "missing");
    std::set<std::uint64_t> seen;
    for (const IniEntry& entry : r.section().entries) {
      auto position = DecimalKey(entry.key);
      if (!position) continue;
      if (*position < 1 || *position > *expected) {
        r.Fail(&entry, entry.key,
               "entry " + std::to_string(*position) + " is not in 1.." + std::to_string(*expected) +
                   " (SupportedObjects)");
      }
      if (!seen.insert(*position).second) r.Fail(&entry, entry.key, "duplicate key");
      auto text = StripInlineComment(entry.value);
      auto index = ParseUnsignedLiteral(text, 0xFFFF);
      if (!index) r.Fail(&entry, entry.key, QuoteForError(text) + " is not an object index (0..0xFFFF)");
      if (!out_.od.Find(static_cast<std::uint16_t>(*index))) {
        auto hex = Hex4(static_cast<std::uint16_t>(*index));
        r.Fail(&entry, entry.key, "object " + hex + " is listed but has no section [" + hex + "]");
      }
    }
    if (seen.size() != *expected) {
      r.Fail(r.Find("SupportedObjects"), "SupportedObjects",
             "says " + std::to_string(*expected) + " but " + std::to_string(seen.size()) + " entries follow");
    }
  }

  void Charge(const SectionReader& r, std::size_t bytes) {
    used_ += bytes;
    if (used_ > kMaxDictionaryBytes) {
      r.FailSection("object dictionary too large (over " + std::to_string(kMaxDictionaryBytes >> 20) +
                    " MiB)");
    }
  }

  const EdsSections& sections_;
  std::string_view file_name_;
  EdsFile& out_;
  std::size_t used_ = 0;
};

}  // namespace

void ReadObjects(const EdsSections& sections, std::string_view file_name, EdsFile& out) {
  ObjectReader(sections, file_name, out).Run();
}

}  // namespace canfleet::canopen
