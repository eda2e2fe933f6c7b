#include "node/canopen/eds/eds_error.hpp"

#include <cstdio>

namespace canfleet::canopen {
namespace {

std::string Compose(const std::string& file, std::size_t line, const std::string& section,
                    const std::string& key, const std::string& detail) {
  std::string out = file.empty() ? std::string("<eds>") : file;
  if (line > 0) out += ":" + std::to_string(line);
  out += ": ";
  if (!section.empty()) out += "[" + section + "] ";
  if (!key.empty()) out += key + ": ";
  return out + detail;
}

}  // namespace

EdsError::EdsError(std::string file, std::size_t line, std::string section, std::string key,
                   std::string detail)
    : std::runtime_error(Compose(file, line, section, key, detail)),
      file_(std::move(file)),
      line_(line),
      section_(std::move(section)),
      key_(std::move(key)),
      detail_(std::move(detail)) {}

std::string QuoteForError(std::string_view text) {
  constexpr std::size_t kMaxShown = 60;
  std::string out = "\"";
  for (std::size_t i = 0; i < text.size() && i < kMaxShown; ++i) {
    auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7F || c == '"' || c == '\\') {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  if (text.size() > kMaxShown) out += "...";
  return out + "\"";
}

}  // namespace canfleet::canopen
