#include "node/devices/eds_dictionary.hpp"

#include <map>
#include <mutex>
#include <optional>
#include <utility>

#include "node/canopen/eds/eds.hpp"

namespace canfleet::devices {

canopen::ObjectDictionary DictionaryFromEdsText(std::string_view text, std::string_view file_name) {
  // Parsing a full device EDS takes a few milliseconds, and tests build hundreds of nodes: the
  // parsed dictionary is cached. Only from the second request for the same text, though: a node
  // process asks once, and a cached copy would double its dictionary's memory (~200 kB of the
  // < 10 MB RSS per node of issue 7) for nothing.
  static std::mutex mutex;
  static std::map<std::pair<const char*, std::size_t>, std::optional<canopen::ObjectDictionary>> parsed;
  std::lock_guard lock(mutex);
  auto [it, first_request] = parsed.try_emplace(std::make_pair(text.data(), text.size()));
  if (first_request) return canopen::ParseEds(text, file_name).od;
  if (!it->second) it->second = canopen::ParseEds(text, file_name).od;
  return *it->second;
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
