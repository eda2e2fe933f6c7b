#include "node/canopen/eds/eds_compare.hpp"

#include <cstdio>

#include "node/canopen/od/value.hpp"

namespace canfleet::canopen {
namespace {

std::string Where(std::uint16_t index) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04X", index);
  return buf;
}

std::string Where(std::uint16_t index, std::uint8_t sub) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%04Xsub%X", index, sub);
  return buf;
}

std::string Hex(const Bytes& bytes) {
  std::string out;
  char buf[4];
  for (auto b : bytes) {
    std::snprintf(buf, sizeof buf, "%02X", b);
    out += buf;
  }
  return out.empty() ? "(empty)" : out;
}

std::string Show(const SmallBytes& bytes) {
  return Hex(bytes);
}
std::string Show(const std::string& text) {
  return "\"" + text + "\"";
}
std::string Show(DataType type) {
  return std::string(ToString(type));
}
std::string Show(Access access) {
  return std::string(ToString(access));
}
std::string Show(ObjectCode code) {
  return std::string(ToString(code));
}
template <typename T>
requires std::is_arithmetic_v<T> std::string Show(T value) {
  return std::to_string(value);
}
template <typename T>
std::string Show(const std::optional<T>& value) {
  return value ? Show(*value) : "(none)";
}
std::string Show(const std::set<std::uint16_t>& values) {
  std::string out;
  for (auto v : values)
    out += (out.empty() ? "" : ",") + std::to_string(v);
  return "{" + out + "}";
}
std::string Show(const std::vector<std::string>& lines) {
  return std::to_string(lines.size()) + " lines";
}

/// Where a difference is; spelled only when there is one (the fuzz target compares every field
/// of every sub-object on each run).
struct Loc {
  const char* section = nullptr;  ///< a file-level section, or null for an object
  std::uint16_t index = 0;
  int sub = -1;  ///< -1 for the object itself
  std::string Text() const {
    if (section) return section;
    return sub < 0 ? Where(index) : Where(index, static_cast<std::uint8_t>(sub));
  }
};

class Differ {
 public:
  template <typename T>
  void Check(const Loc& where, const char* what, const T& a, const T& b) {
    if (!(a == b)) out_.push_back(where.Text() + " " + what + ": " + Show(a) + " != " + Show(b));
  }
  void Note(std::string line) { out_.push_back(std::move(line)); }
  std::vector<std::string> Take() { return std::move(out_); }

 private:
  std::vector<std::string> out_;
};

void DiffSub(Differ& d, const SubObject& a, const SubObject& b, bool compare_values) {
  const Loc where{nullptr, a.index, a.sub_index};
  d.Check(where, "ParameterName", a.name, b.name);
  d.Check(where, "DataType", a.type, b.type);
  d.Check(where, "AccessType", a.access, b.access);
  d.Check(where, "PDOMapping", a.pdo_mappable, b.pdo_mappable);
  d.Check(where, "LowLimit", a.low_limit, b.low_limit);
  d.Check(where, "HighLimit", a.high_limit, b.high_limit);
  d.Check(where, "DefaultValue", a.default_value, b.default_value);
  d.Check(where, "$NODEID default", a.default_adds_node_id, b.default_adds_node_id);
  d.Check(where, "ObjFlags", a.obj_flags, b.obj_flags);
  if (compare_values) d.Check(where, "value", a.value, b.value);
}

void DiffOd(Differ& d, const ObjectDictionary& a, const ObjectDictionary& b, bool compare_values) {
  for (const auto& [index, obj] : a.objects()) {
    const Object* other = b.Find(index);
    if (!other) {
      d.Note(Where(index) + " missing from the second dictionary");
      continue;
    }
    const Loc where{nullptr, index, -1};
    d.Check(where, "ParameterName", obj.name, other->name);
    d.Check(where, "ObjectType", obj.code, other->code);
    d.Check(where, "ObjFlags", obj.obj_flags, other->obj_flags);
    for (const auto& [sub_index, sub] : obj.subs) {
      auto it = other->subs.find(sub_index);
      if (it == other->subs.end()) {
        d.Note(Where(index, sub_index) + " missing from the second dictionary");
        continue;
      }
      DiffSub(d, sub, it->second, compare_values);
    }
    for (const auto& [sub_index, sub] : other->subs) {
      if (!obj.subs.contains(sub_index))
        d.Note(Where(index, sub_index) + " missing from the first dictionary");
    }
  }
  for (const auto& [index, obj] : b.objects()) {
    if (!a.Find(index)) d.Note(Where(index) + " missing from the first dictionary");
  }
}

}  // namespace

std::vector<std::string> DiffObjectDictionaries(const ObjectDictionary& a, const ObjectDictionary& b,
                                                bool compare_values) {
  Differ d;
  DiffOd(d, a, b, compare_values);
  return d.Take();
}

std::vector<std::string> DiffEdsFiles(const EdsFile& a, const EdsFile& b, EdsFormat format) {
  Differ d;
  const bool dcf = format == EdsFormat::kDcf;
  DiffOd(d, a.od, b.od, dcf);
  for (const auto& [key, limits] : a.node_id_limits) {
    auto it = b.node_id_limits.find(key);
    NodeIdLimits other = it == b.node_id_limits.end() ? NodeIdLimits{} : it->second;
    const Loc where{nullptr, key.first, key.second};
    d.Check(where, "$NODEID LowLimit", limits.low, other.low);
    d.Check(where, "$NODEID HighLimit", limits.high, other.high);
  }
  for (const auto& [key, limits] : b.node_id_limits) {
    if (!a.node_id_limits.contains(key))
      d.Note(Where(key.first, key.second) + " $NODEID limit only in the second");
  }
  const auto& fa = a.file_info;
  const auto& fb = b.file_info;
  d.Check(Loc{"FileInfo"}, "FileName", fa.file_name, fb.file_name);
  d.Check(Loc{"FileInfo"}, "FileVersion", fa.file_version, fb.file_version);
  d.Check(Loc{"FileInfo"}, "FileRevision", fa.file_revision, fb.file_revision);
  d.Check(Loc{"FileInfo"}, "EDSVersion", fa.eds_version, fb.eds_version);
  d.Check(Loc{"FileInfo"}, "Description", fa.description, fb.description);
  d.Check(Loc{"FileInfo"}, "CreationTime", fa.creation_time, fb.creation_time);
  d.Check(Loc{"FileInfo"}, "CreationDate", fa.creation_date, fb.creation_date);
  d.Check(Loc{"FileInfo"}, "CreatedBy", fa.created_by, fb.created_by);
  d.Check(Loc{"FileInfo"}, "ModificationTime", fa.modification_time, fb.modification_time);
  d.Check(Loc{"FileInfo"}, "ModificationDate", fa.modification_date, fb.modification_date);
  d.Check(Loc{"FileInfo"}, "ModifiedBy", fa.modified_by, fb.modified_by);
  d.Check(Loc{"FileInfo"}, "LastEDS", fa.last_eds, fb.last_eds);
  const auto& da = a.device_info;
  const auto& db = b.device_info;
  d.Check(Loc{"DeviceInfo"}, "VendorName", da.vendor_name, db.vendor_name);
  d.Check(Loc{"DeviceInfo"}, "VendorNumber", da.vendor_number, db.vendor_number);
  d.Check(Loc{"DeviceInfo"}, "ProductName", da.product_name, db.product_name);
  d.Check(Loc{"DeviceInfo"}, "ProductNumber", da.product_number, db.product_number);
  d.Check(Loc{"DeviceInfo"}, "RevisionNumber", da.revision_number, db.revision_number);
  d.Check(Loc{"DeviceInfo"}, "OrderCode", da.order_code, db.order_code);
  d.Check(Loc{"DeviceInfo"}, "BaudRate_*", da.baud_rates_kbit, db.baud_rates_kbit);
  d.Check(Loc{"DeviceInfo"}, "SimpleBootUpMaster", da.simple_boot_up_master, db.simple_boot_up_master);
  d.Check(Loc{"DeviceInfo"}, "SimpleBootUpSlave", da.simple_boot_up_slave, db.simple_boot_up_slave);
  d.Check(Loc{"DeviceInfo"}, "Granularity", da.granularity, db.granularity);
  d.Check(Loc{"DeviceInfo"}, "DynamicChannelsSupported", da.dynamic_channels_supported,
          db.dynamic_channels_supported);
  d.Check(Loc{"DeviceInfo"}, "GroupMessaging", da.group_messaging, db.group_messaging);
  d.Check(Loc{"DeviceInfo"}, "NrOfRXPDO", da.nr_of_rx_pdo, db.nr_of_rx_pdo);
  d.Check(Loc{"DeviceInfo"}, "NrOfTXPDO", da.nr_of_tx_pdo, db.nr_of_tx_pdo);
  d.Check(Loc{"DeviceInfo"}, "LSS_Supported", da.lss_supported, db.lss_supported);
  d.Check(Loc{"DeviceInfo"}, "CompactPDO", da.compact_pdo, db.compact_pdo);
  d.Check(Loc{"DummyUsage"}, "bits", a.dummy_usage, b.dummy_usage);
  d.Check(Loc{"Comments"}, "lines", a.comments, b.comments);
  if (dcf) {
    d.Check(Loc{"DeviceComissioning"}, "NodeID", a.dcf_node_id, b.dcf_node_id);
    d.Check(Loc{"DeviceComissioning"}, "Baudrate", a.dcf_baudrate_kbit, b.dcf_baudrate_kbit);
    d.Check(Loc{"DeviceComissioning"}, "NodeName", a.commissioning.node_name, b.commissioning.node_name);
    d.Check(Loc{"DeviceComissioning"}, "NetNumber", a.commissioning.net_number, b.commissioning.net_number);
    d.Check(Loc{"DeviceComissioning"}, "NetworkName", a.commissioning.network_name,
            b.commissioning.network_name);
    d.Check(Loc{"DeviceComissioning"}, "CANopenManager", a.commissioning.canopen_manager,
            b.commissioning.canopen_manager);
    d.Check(Loc{"DeviceComissioning"}, "LSS_SerialNumber", a.commissioning.lss_serial_number,
            b.commissioning.lss_serial_number);
  }
  return d.Take();
}

}  // namespace canfleet::canopen
