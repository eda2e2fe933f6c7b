#include "node/canopen/eds/eds_file_info.hpp"

#include <cstdint>
#include <limits>
#include <string>

#include "node/canopen/eds/eds_error.hpp"
#include "node/canopen/eds/eds_number.hpp"
#include "node/canopen/eds/ini_section.hpp"

namespace canfleet::canopen {
namespace {

constexpr std::uint64_t kU8 = 0xFF;
constexpr std::uint64_t kU16 = 0xFFFF;
constexpr std::uint64_t kU32 = 0xFFFFFFFF;

std::string Text(const SectionReader& r, std::string_view key) {
  return std::string(r.Value(key).value_or(""));
}

bool IsDigit(char c) {
  return c >= '0' && c <= '9';
}

std::string Checked(const SectionReader& r, std::string_view key, bool (*valid)(std::string_view),
                    std::string_view format) {
  auto value = r.Value(key);
  if (!value) return "";
  if (!valid(*value))
    r.Fail(r.Find(key), r.Find(key)->key, QuoteForError(*value) + " is not " + std::string(format));
  return std::string(*value);
}

template <typename T>
T Number(const SectionReader& r, std::string_view key, T fallback = 0) {
  return static_cast<T>(r.Unsigned(key, std::numeric_limits<T>::max()).value_or(fallback));
}

void ReadFileInfo(const SectionReader& r, FileInfo& out) {
  out.file_name = Text(r, "FileName");
  out.file_version = Number<std::uint8_t>(r, "FileVersion", out.file_version);
  out.file_revision = Number<std::uint8_t>(r, "FileRevision", out.file_revision);
  out.eds_version = r.Value("EDSVersion") ? Text(r, "EDSVersion") : out.eds_version;
  out.description = Text(r, "Description");
  out.creation_time = Checked(r, "CreationTime", IsEdsTime, "a time (hh:mmAM)");
  out.creation_date = Checked(r, "CreationDate", IsEdsDate, "a date (mm-dd-yyyy)");
  out.created_by = Text(r, "CreatedBy");
  out.modification_time = Checked(r, "ModificationTime", IsEdsTime, "a time (hh:mmAM)");
  out.modification_date = Checked(r, "ModificationDate", IsEdsDate, "a date (mm-dd-yyyy)");
  out.modified_by = Text(r, "ModifiedBy");
  out.last_eds = Text(r, "LastEDS");
}

void ReadDeviceInfo(const SectionReader& r, DeviceInfo& out) {
  out.vendor_name = Text(r, "VendorName");
  out.vendor_number = Number<std::uint32_t>(r, "VendorNumber");
  out.product_name = Text(r, "ProductName");
  out.product_number = Number<std::uint32_t>(r, "ProductNumber");
  out.revision_number = Number<std::uint32_t>(r, "RevisionNumber");
  out.order_code = Text(r, "OrderCode");
  for (std::uint16_t kbit : kEdsBaudRatesKbit) {
    if (r.Flag("BaudRate_" + std::to_string(kbit)).value_or(false)) out.baud_rates_kbit.insert(kbit);
  }
  out.simple_boot_up_master = r.Flag("SimpleBootUpMaster").value_or(false);
  out.simple_boot_up_slave = r.Flag("SimpleBootUpSlave").value_or(false);
  // CiA 306 §4.4: Granularity 0..64, the bit granularity of PDO mapping.
  out.granularity = static_cast<std::uint8_t>(r.Unsigned("Granularity", 64).value_or(0));
  out.dynamic_channels_supported = Number<std::uint8_t>(r, "DynamicChannelsSupported");
  out.group_messaging = r.Flag("GroupMessaging").value_or(false);
  out.nr_of_rx_pdo = Number<std::uint16_t>(r, "NrOfRxPDO");
  out.nr_of_tx_pdo = Number<std::uint16_t>(r, "NrOfTxPDO");
  out.lss_supported = r.Flag("LSS_Supported").value_or(false);
  if (auto compact = r.Unsigned("CompactPDO", kU8)) out.compact_pdo = static_cast<std::uint8_t>(*compact);
}

/// CiA 306 §4.5 [DummyUsage]: Dummy0001=1 ... Dummy0007=0, keyed by data type index in hex.
void ReadDummyUsage(const SectionReader& r, std::uint32_t& out) {
  for (const IniEntry& entry : r.section().entries) {
    auto key = ToLowerAscii(entry.key);
    if (key.size() != 9 || !key.starts_with("dummy")) continue;
    auto index = ParseUnsignedLiteral("0x" + key.substr(5), 0xFFFF);
    if (!index || *index >= 32) continue;
    if (r.Flag(entry.key).value_or(false)) out |= std::uint32_t{1} << *index;
  }
}

/// CiA 306 [Comments]: Lines=n, then Line1 ... Linen.
void ReadComments(const SectionReader& r, std::vector<std::string>& out) {
  auto lines = r.Unsigned("Lines", kU16);
  if (!lines) return;
  for (std::uint64_t i = 1; i <= *lines; ++i) {
    auto key = "Line" + std::to_string(i);
    const IniEntry* entry = r.Find(key);
    if (!entry)
      r.Fail(r.Find("Lines"), "Lines", "says " + std::to_string(*lines) + " but " + key + " is missing");
    out.emplace_back(entry->value);
  }
}

/// CiA 306 §5 [DeviceComissioning] (DCF).
void ReadCommissioning(const SectionReader& r, EdsFile& out) {
  if (auto node_id = r.Unsigned("NodeID", kU8)) {
    const IniEntry* entry = r.Find("NodeID");
    if (*node_id < 1 || *node_id > 127) {
      r.Fail(entry, entry->key,
             QuoteForError(StripInlineComment(entry->value)) + " is out of range (1..127)");
    }
    out.dcf_node_id = static_cast<std::uint8_t>(*node_id);
  }
  if (auto baud = r.Unsigned("Baudrate", kU32)) out.dcf_baudrate_kbit = static_cast<std::uint32_t>(*baud);
  auto& c = out.commissioning;
  c.node_name = Text(r, "NodeName");
  if (auto net = r.Unsigned("NetNumber", kU32)) c.net_number = static_cast<std::uint32_t>(*net);
  c.network_name = Text(r, "NetworkName");
  c.canopen_manager = r.Flag("CANopenManager");
  if (auto serial = r.Unsigned("LSS_SerialNumber", kU32))
    c.lss_serial_number = static_cast<std::uint32_t>(*serial);
}

}  // namespace

bool IsEdsTime(std::string_view text) {
  std::size_t i = 0;
  while (i < text.size() && IsDigit(text[i]))
    ++i;
  if (i < 1 || i > 2 || i + 3 > text.size() || text[i] != ':' || !IsDigit(text[i + 1]) ||
      !IsDigit(text[i + 2])) {
    return false;
  }
  auto rest = ToLowerAscii(TrimBlanks(text.substr(i + 3)));
  return rest.empty() || rest == "am" || rest == "pm";
}

bool IsEdsDate(std::string_view text) {
  if (text.size() != 10 || text[2] != '-' || text[5] != '-') return false;
  for (std::size_t i : {0, 1, 3, 4, 6, 7, 8, 9}) {
    if (!IsDigit(text[i])) return false;
  }
  return true;
}

void ReadFileLevelSections(const EdsSections& sections, std::string_view file_name, EdsFile& out) {
  if (sections.file_info) ReadFileInfo(SectionReader(*sections.file_info, file_name), out.file_info);
  if (sections.device_info) ReadDeviceInfo(SectionReader(*sections.device_info, file_name), out.device_info);
  if (sections.dummy_usage) ReadDummyUsage(SectionReader(*sections.dummy_usage, file_name), out.dummy_usage);
  if (sections.comments) ReadComments(SectionReader(*sections.comments, file_name), out.comments);
  if (sections.commissioning) ReadCommissioning(SectionReader(*sections.commissioning, file_name), out);
}

}  // namespace canfleet::canopen
