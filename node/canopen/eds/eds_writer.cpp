#include "node/canopen/eds/eds_writer.hpp"

#include <cstdio>
#include <ostream>
#include <string_view>
#include <vector>

#include "node/canopen/eds/eds_file_info.hpp"
#include "node/canopen/eds/eds_value.hpp"

namespace canfleet::canopen {
namespace {

std::string Printf(const char* format, unsigned long long value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, format, value);
  return buf;
}

std::string Hex(unsigned long long value, int digits) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "0x%0*llX", digits, value);
  return buf;
}

std::string Decimal(unsigned long long value) {
  return Printf("%llu", value);
}

class Writer {
 public:
  explicit Writer(EdsFormat format) : format_(format) {}

  std::string Write(const EdsFile& file) {
    WriteFileInfo(file.file_info);
    WriteDeviceInfo(file.device_info);
    WriteDummyUsage(file.dummy_usage);
    WriteComments(file.comments);
    if (format_ == EdsFormat::kDcf) WriteCommissioning(file);
    std::vector<const Object*> lists[3];
    for (const auto& [index, obj] : file.od.objects())
      lists[static_cast<int>(ObjectListFor(index))].push_back(&obj);
    const char* names[3] = {"MandatoryObjects", "OptionalObjects", "ManufacturerObjects"};
    for (int list = 0; list < 3; ++list) {
      Section(names[list]);
      Key("SupportedObjects", Decimal(lists[list].size()));
      for (std::size_t i = 0; i < lists[list].size(); ++i)
        Key(Decimal(i + 1), Hex(lists[list][i]->index, 4));
      for (const Object* obj : lists[list])
        WriteObject(*obj, file);
    }
    return std::move(text_);
  }

 private:
  void Section(std::string name) {
    if (!text_.empty()) text_ += '\n';
    section_ = std::move(name);
    text_ += "[" + section_ + "]\n";
  }

  void Key(std::string_view key, std::string_view value) {
    if (!IsWritableText(value))
      Fail(key, "cannot be written: line break, control character or leading/trailing blank");
    text_.append(key).append("=").append(value).append("\n");
  }

  [[noreturn]] void Fail(std::string_view key, std::string detail) {
    throw EdsError("<output>", 0, section_, std::string(key), std::move(detail));
  }

  void WriteFileInfo(const FileInfo& info) {
    Section("FileInfo");
    Key("FileName", info.file_name);
    Key("FileVersion", Decimal(info.file_version));
    Key("FileRevision", Decimal(info.file_revision));
    Key("EDSVersion", info.eds_version);
    Key("Description", info.description);
    Key("CreationTime", info.creation_time);
    Key("CreationDate", info.creation_date);
    Key("CreatedBy", info.created_by);
    Key("ModificationTime", info.modification_time);
    Key("ModificationDate", info.modification_date);
    Key("ModifiedBy", info.modified_by);
    if (!info.last_eds.empty()) Key("LastEDS", info.last_eds);
  }

  void WriteDeviceInfo(const DeviceInfo& info) {
    Section("DeviceInfo");
    Key("VendorName", info.vendor_name);
    Key("VendorNumber", Hex(info.vendor_number, 8));
    Key("ProductName", info.product_name);
    Key("ProductNumber", Hex(info.product_number, 8));
    Key("RevisionNumber", Hex(info.revision_number, 8));
    Key("OrderCode", info.order_code);
    for (std::uint16_t kbit : kEdsBaudRatesKbit) {
      Key("BaudRate_" + Decimal(kbit), info.baud_rates_kbit.contains(kbit) ? "1" : "0");
    }
    Key("SimpleBootUpMaster", Decimal(info.simple_boot_up_master));
    Key("SimpleBootUpSlave", Decimal(info.simple_boot_up_slave));
    Key("Granularity", Decimal(info.granularity));
    Key("DynamicChannelsSupported", Decimal(info.dynamic_channels_supported));
    Key("GroupMessaging", Decimal(info.group_messaging));
    Key("NrOfRXPDO", Decimal(info.nr_of_rx_pdo));
    Key("NrOfTXPDO", Decimal(info.nr_of_tx_pdo));
    Key("LSS_Supported", Decimal(info.lss_supported));
    if (info.compact_pdo) Key("CompactPDO", Hex(*info.compact_pdo, 2));
  }

  void WriteDummyUsage(std::uint32_t dummy_usage) {
    Section("DummyUsage");
    for (unsigned type = 0; type < 32; ++type) {
      const bool used = (dummy_usage >> type) & 1;
      // CiA 306 lists Dummy0001..Dummy0007; other types only when set.
      if (used || (type >= 1 && type <= 7)) Key(Printf("Dummy%04llX", type), used ? "1" : "0");
    }
  }

  void WriteComments(const std::vector<std::string>& comments) {
    if (comments.empty()) return;
    Section("Comments");
    Key("Lines", Decimal(comments.size()));
    for (std::size_t i = 0; i < comments.size(); ++i)
      Key("Line" + Decimal(i + 1), comments[i]);
  }

  void WriteCommissioning(const EdsFile& file) {
    Section("DeviceComissioning");  // sic: the CiA 306 spelling
    const auto& c = file.commissioning;
    if (file.dcf_node_id) Key("NodeID", Decimal(*file.dcf_node_id));
    Key("NodeName", c.node_name);
    if (file.dcf_baudrate_kbit) Key("Baudrate", Decimal(*file.dcf_baudrate_kbit));
    if (c.net_number) Key("NetNumber", Decimal(*c.net_number));
    Key("NetworkName", c.network_name);
    if (c.canopen_manager) Key("CANopenManager", Decimal(*c.canopen_manager));
    if (c.lss_serial_number) Key("LSS_SerialNumber", Hex(*c.lss_serial_number, 8));
  }

  void WriteObject(const Object& obj, const EdsFile& file) {
    const std::string index = Hex(obj.index, 4).substr(2);
    Section(index);
    Key("ParameterName", obj.name);
    Key("ObjectType", Hex(static_cast<unsigned>(obj.code), 1));
    const bool var_like =
        obj.code == ObjectCode::kVar || obj.code == ObjectCode::kDomain || obj.code == ObjectCode::kDefType;
    if (var_like) {
      auto sub0 = obj.subs.find(0);
      if (sub0 == obj.subs.end() || obj.subs.size() != 1) {
        Fail("", std::string(ToString(obj.code)) + " object needs exactly one sub-object, at sub-index 0");
      }
      const SubObject& sub = sub0->second;
      WriteValueKeys(sub, file, obj.obj_flags != 0 ? obj.obj_flags : sub.obj_flags);
      return;
    }
    if (obj.subs.size() > 255) Fail("SubNumber", "more than 255 sub-objects");
    Key("SubNumber", Hex(obj.subs.size(), 1));
    if (obj.obj_flags != 0) Key("ObjFlags", Hex(obj.obj_flags, 1));
    for (const auto& [sub_index, sub] : obj.subs) {
      Section(index + "sub" + Hex(sub_index, 1).substr(2));
      Key("ParameterName", sub.name);
      Key("ObjectType", "0x7");
      WriteValueKeys(sub, file, sub.obj_flags);
    }
  }

  /// CiA 306 §4.6.3.2 keys of one value; a DCF adds ParameterValue (§5).
  void WriteValueKeys(const SubObject& sub, const EdsFile& file, std::uint32_t obj_flags) {
    if (!IsKnown(sub.type))
      Fail("DataType", Hex(static_cast<unsigned>(sub.type), 4) + " is not a known data type");
    Key("DataType", Hex(static_cast<unsigned>(sub.type), 4));
    Key("AccessType", ToString(sub.access));
    Key("DefaultValue", Format(sub, "DefaultValue", sub.default_value, sub.default_adds_node_id));
    Key("PDOMapping", sub.pdo_mappable ? "1" : "0");
    if (!IsVariableLength(sub.type)) {
      NodeIdLimits node_id;
      if (auto it = file.node_id_limits.find({sub.index, sub.sub_index}); it != file.node_id_limits.end()) {
        node_id = it->second;
      }
      if (sub.low_limit) Key("LowLimit", Format(sub, "LowLimit", *sub.low_limit, node_id.low));
      if (sub.high_limit) Key("HighLimit", Format(sub, "HighLimit", *sub.high_limit, node_id.high));
    }
    if (obj_flags != 0) Key("ObjFlags", Hex(obj_flags, 1));
    if (format_ == EdsFormat::kDcf) Key("ParameterValue", Format(sub, "ParameterValue", sub.value, false));
  }

  std::string Format(const SubObject& sub, std::string_view key, const Bytes& bytes, bool adds_node_id) {
    if (auto size = FixedSize(sub.type); size && bytes.size() != *size) {
      Fail(key, Decimal(bytes.size()) + " bytes for " + std::string(ToString(sub.type)) + ", which has " +
                    Decimal(*size));
    }
    return FormatEdsValue(sub.type, bytes, adds_node_id);
  }

  EdsFormat format_;
  std::string text_;
  std::string section_;
};

}  // namespace

EdsObjectList ObjectListFor(std::uint16_t index) {
  if (index == 0x1000 || index == 0x1001 || index == 0x1018) return EdsObjectList::kMandatory;
  if (index >= 0x2000 && index <= 0x5FFF) return EdsObjectList::kManufacturer;
  return EdsObjectList::kOptional;
}

std::string WriteEdsString(const EdsFile& file, EdsFormat format) {
  return Writer(format).Write(file);
}

void WriteEds(const EdsFile& file, std::ostream& out, EdsFormat format) {
  out << WriteEdsString(file, format);
}

void StampFileInfo(FileInfo& info, std::chrono::system_clock::time_point when) {
  using namespace std::chrono;
  const auto day = floor<days>(when);
  const year_month_day date{day};
  const hh_mm_ss time{floor<minutes>(when - day)};
  char date_text[16];
  std::snprintf(date_text, sizeof date_text, "%02u-%02u-%04d", static_cast<unsigned>(date.month()),
                static_cast<unsigned>(date.day()), static_cast<int>(date.year()));
  const long hour = time.hours().count();
  char time_text[16];
  std::snprintf(time_text, sizeof time_text, "%02ld:%02ld%s", hour % 12 == 0 ? 12 : hour % 12,
                static_cast<long>(time.minutes().count()), hour < 12 ? "AM" : "PM");
  info.modification_date = date_text;
  info.modification_time = time_text;
  if (info.creation_date.empty()) info.creation_date = date_text;
  if (info.creation_time.empty()) info.creation_time = time_text;
}

}  // namespace canfleet::canopen
