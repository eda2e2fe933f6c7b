#include "node/devices/dictionary/table_facts.hpp"

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <string>

#include "node/canopen/eds/eds_file_info.hpp"
#include "node/canopen/eds/eds_number.hpp"
#include "node/devices/dictionary/od_table.hpp"
#include "node/devices/dictionary/table_lines.hpp"

namespace canfleet::devices::od_table {
namespace {

struct FactContext {
  std::string_view value;
  std::string_view file;
  std::size_t line;
  std::string_view key;

  [[noreturn]] void Fail(const std::string& detail) const {
    throw OdTableError(std::string(file), line, "@" + std::string(key), detail);
  }
  template <typename T>
  T Number() const {
    auto n = canopen::ParseUnsignedLiteral(value, std::numeric_limits<T>::max());
    if (!n)
      Fail("\"" + std::string(value) + "\" is not a number from 0 to " +
           std::to_string(std::numeric_limits<T>::max()));
    return static_cast<T>(*n);
  }
  bool Flag() const { return Number<std::uint8_t>() != 0; }
  /// Each blank-separated word as a number.
  template <typename T, typename Each>
  void ForEachNumber(Each each) const {
    std::string_view rest = value;
    while (!rest.empty()) {
      auto end = rest.find_first_of(" \t,");
      FactContext word = *this;
      word.value = rest.substr(0, end);
      if (!word.value.empty()) each(word.template Number<T>());
      rest.remove_prefix(end == std::string_view::npos ? rest.size() : end + 1);
    }
  }
};

using Setter = std::function<void(const FactContext&, canopen::EdsFile&, FactsSeen&)>;

template <typename T>
Setter Text(T canopen::FileInfo::*field) {
  return [field](const FactContext& c, canopen::EdsFile& f, FactsSeen&) {
    f.file_info.*field = std::string(c.value);
  };
}
/// A date or time fact, in the spelling the EDS reader takes back (CiA 306 §4.3).
Setter Checked(std::string canopen::FileInfo::*field, bool (*valid)(std::string_view),
               std::string_view format) {
  return [field, valid, format](const FactContext& c, canopen::EdsFile& f, FactsSeen&) {
    if (!valid(c.value)) c.Fail("\"" + std::string(c.value) + "\" is not " + std::string(format));
    f.file_info.*field = std::string(c.value);
  };
}
Setter DeviceText(std::string canopen::DeviceInfo::*field) {
  return [field](const FactContext& c, canopen::EdsFile& f, FactsSeen&) {
    f.device_info.*field = std::string(c.value);
  };
}
template <typename T>
Setter DeviceNumber(T canopen::DeviceInfo::*field) {
  return [field](const FactContext& c, canopen::EdsFile& f, FactsSeen&) {
    f.device_info.*field = c.Number<T>();
  };
}
Setter DeviceFlag(bool canopen::DeviceInfo::*field) {
  return [field](const FactContext& c, canopen::EdsFile& f, FactsSeen&) { f.device_info.*field = c.Flag(); };
}

const std::map<std::string_view, Setter>& Setters() {
  using canopen::DeviceInfo;
  using canopen::FileInfo;
  static const std::map<std::string_view, Setter> setters = {
      {"file_name", Text(&FileInfo::file_name)},
      {"description", Text(&FileInfo::description)},
      {"creation_date", Checked(&FileInfo::creation_date, canopen::IsEdsDate, "a date (mm-dd-yyyy)")},
      {"creation_time", Checked(&FileInfo::creation_time, canopen::IsEdsTime, "a time (hh:mmAM)")},
      {"created_by", Text(&FileInfo::created_by)},
      {"modification_date", Checked(&FileInfo::modification_date, canopen::IsEdsDate, "a date (mm-dd-yyyy)")},
      {"modification_time", Checked(&FileInfo::modification_time, canopen::IsEdsTime, "a time (hh:mmAM)")},
      {"modified_by", Text(&FileInfo::modified_by)},
      {"file_version", [](const FactContext& c, canopen::EdsFile& f,
                          FactsSeen&) { f.file_info.file_version = c.Number<std::uint8_t>(); }},
      {"file_revision", [](const FactContext& c, canopen::EdsFile& f,
                           FactsSeen&) { f.file_info.file_revision = c.Number<std::uint8_t>(); }},
      {"vendor_name", DeviceText(&DeviceInfo::vendor_name)},
      {"product_name", DeviceText(&DeviceInfo::product_name)},
      {"order_code", DeviceText(&DeviceInfo::order_code)},
      {"vendor_number", DeviceNumber(&DeviceInfo::vendor_number)},
      {"product_number", DeviceNumber(&DeviceInfo::product_number)},
      {"revision_number", DeviceNumber(&DeviceInfo::revision_number)},
      {"granularity", DeviceNumber(&DeviceInfo::granularity)},
      {"dynamic_channels_supported", DeviceNumber(&DeviceInfo::dynamic_channels_supported)},
      {"simple_boot_up_master", DeviceFlag(&DeviceInfo::simple_boot_up_master)},
      {"simple_boot_up_slave", DeviceFlag(&DeviceInfo::simple_boot_up_slave)},
      {"group_messaging", DeviceFlag(&DeviceInfo::group_messaging)},
      {"lss_supported", DeviceFlag(&DeviceInfo::lss_supported)},
      {"nr_of_rx_pdo",
       [](const FactContext& c, canopen::EdsFile& f, FactsSeen& seen) {
         f.device_info.nr_of_rx_pdo = c.Number<std::uint16_t>();
         seen.nr_of_rx_pdo = true;
       }},
      {"nr_of_tx_pdo",
       [](const FactContext& c, canopen::EdsFile& f, FactsSeen& seen) {
         f.device_info.nr_of_tx_pdo = c.Number<std::uint16_t>();
         seen.nr_of_tx_pdo = true;
       }},
      {"baud_rates",
       [](const FactContext& c, canopen::EdsFile& f, FactsSeen&) {
         c.ForEachNumber<std::uint16_t>([&](std::uint16_t kbit) {
           static const std::set<std::uint16_t> kCia306 = {10, 20, 50, 125, 250, 500, 800, 1000};
           if (!kCia306.contains(kbit))
             c.Fail(std::to_string(kbit) + " kbit/s is not a CiA 306 BaudRate_ key");
           f.device_info.baud_rates_kbit.insert(kbit);
         });
       }},
      {"dummy_usage",
       [](const FactContext& c, canopen::EdsFile& f, FactsSeen&) {
         c.ForEachNumber<std::uint8_t>([&](std::uint8_t type) {
           if (type > 31) c.Fail("dummy data type " + std::to_string(type) + " is above 31");
           f.dummy_usage |= 1U << type;
         });
       }},
      {"comment",
       [](const FactContext& c, canopen::EdsFile& f, FactsSeen&) { f.comments.emplace_back(c.value); }},
  };
  return setters;
}

}  // namespace

void ApplyFact(std::string_view line, std::string_view file_name, std::size_t line_number,
               canopen::EdsFile& out, FactsSeen& seen) {
  auto space = line.find_first_of(" \t");
  std::string_view key = line.substr(0, space);
  std::string_view value = space == std::string_view::npos ? std::string_view() : Trim(line.substr(space));
  const auto& setters = Setters();
  auto it = setters.find(key);
  if (it == setters.end()) {
    std::string known;
    for (const auto& [name, setter] : setters)
      known += (known.empty() ? "@" : ", @") + std::string(name);
    throw OdTableError(std::string(file_name), line_number, "",
                       "unknown fact \"@" + std::string(key) + "\" (known: " + known + ")");
  }
  it->second(FactContext{value, file_name, line_number, key}, out, seen);
}

}  // namespace canfleet::devices::od_table
