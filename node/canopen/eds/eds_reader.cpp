#include "node/canopen/eds/eds_reader.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>

#include "node/canopen/eds/eds_file_info.hpp"
#include "node/canopen/eds/eds_objects.hpp"
#include "node/canopen/eds/eds_sections.hpp"
#include "node/canopen/eds/ini_lexer.hpp"

namespace canfleet::canopen {

EdsFile ReadEds(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  auto size = std::filesystem::file_size(path, ec);
  if (ec) throw EdsError(name, 0, "", "", "cannot read: " + ec.message());
  if (size > kMaxEdsFileBytes) {
    throw EdsError(name, 0, "", "", "file too large for an EDS (" + std::to_string(size) + " bytes)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw EdsError(name, 0, "", "", std::string("cannot open: ") + std::strerror(errno));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw EdsError(name, 0, "", "", "read error");
  return ParseEds(text, name);
}

EdsFile ParseEds(std::string_view text, std::string_view file_name) {
  const auto sections = LexIni(text, file_name);
  const EdsSections classified = ClassifySections(sections, file_name);
  EdsFile out;
  // File-level sections first: the DCF NodeID is needed to resolve "$NODEID" in ParameterValue.
  ReadFileLevelSections(classified, file_name, out);
  ReadObjects(classified, file_name, out);
  return out;
}

}  // namespace canfleet::canopen
