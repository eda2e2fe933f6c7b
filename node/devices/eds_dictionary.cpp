#include "node/devices/eds_dictionary.hpp"

#include <map>
#include <mutex>
#include <optional>
#include <utility>

#include "node/canopen/eds/eds.hpp"

namespace canfleet::devices {

canopen::ObjectDictionary DictionaryFromEmbeddedEds(const EmbeddedEds& eds, std::string_view file_name) {
  // Parsing a full device EDS takes a few milliseconds, and tests build hundreds of nodes: the
  // parsed dictionary is cached. Only from the second request for the same text, though: a node
  // process asks once, and a cached copy would double its dictionary's memory (~200 kB of the
  // < 10 MB RSS per node of issue 7) for nothing.
  static std::mutex mutex;
  static std::map<const std::uint8_t*, std::optional<canopen::ObjectDictionary>> parsed;
  std::lock_guard lock(mutex);
  auto [it, first_request] = parsed.try_emplace(eds.deflated.data());
  if (first_request) return canopen::ParseEds(eds.Text(), file_name).od;
  if (!it->second) it->second = canopen::ParseEds(eds.Text(), file_name).od;
  return *it->second;
}

canopen::ObjectDictionary DictionaryFromEdsFile(const std::filesystem::path& path) {
  return canopen::ReadEds(path).od;
}

canopen::ObjectDictionary LoadVariantDictionary(const EmbeddedEds& eds, std::string_view file_name,
                                                const std::filesystem::path& override_path) {
  if (!override_path.empty()) return DictionaryFromEdsFile(override_path);
  return DictionaryFromEmbeddedEds(eds, file_name);
}

}  // namespace canfleet::devices
