#include "node/devices/eds_dictionary.hpp"

#include <map>
#include <mutex>
#include <utility>

#include "node/canopen/eds/eds.hpp"

namespace canfleet::devices {

canopen::ObjectDictionary DictionaryFromEdsText(std::string_view text, std::string_view file_name) {
  // Parsing a full device EDS takes a few milliseconds; tests build hundreds of nodes.
  static std::mutex mutex;
  static std::map<std::pair<const char*, std::size_t>, canopen::ObjectDictionary> parsed;
  std::lock_guard lock(mutex);
  auto key = std::make_pair(text.data(), text.size());
  auto it = parsed.find(key);
  if (it == parsed.end()) it = parsed.emplace(key, canopen::ParseEds(text, file_name).od).first;
  return it->second;
}

canopen::ObjectDictionary DictionaryFromEdsFile(const std::filesystem::path& path) {
  return canopen::ReadEds(path).od;
}

canopen::ObjectDictionary LoadVariantDictionary(std::string_view text, std::string_view file_name,
                                                const std::filesystem::path& override_path) {
  if (!override_path.empty()) return DictionaryFromEdsFile(override_path);
  return DictionaryFromEdsText(text, file_name);
}

}  // namespace canfleet::devices
