#include "tools/telemetry/text_fit.hpp"

#include <algorithm>
#include <numeric>
#include <optional>

#include "telemetry/types.hpp"

namespace canfleet::tools {

namespace {

/// A cuttable part is kept cut only with this much room: less would say nothing but "...".
constexpr std::size_t kMinCut = 12;

}  // namespace

std::string FitLine(std::string_view text, int width) {
  if (width <= 0 || text.size() <= static_cast<std::size_t>(width)) return std::string(text);
  const std::size_t n = telemetry::CutAtWord(text, static_cast<std::size_t>(width));
  std::string out(text.substr(0, n));
  if (out.size() + telemetry::kCutMarker.size() <= static_cast<std::size_t>(width))
    out += telemetry::kCutMarker;
  return out;
}

std::string FitCell(std::string_view text, int width, bool right_aligned) {
  if (width <= 0) return "";
  const auto w = static_cast<std::size_t>(width);
  if (text.size() > w) return std::string(text.substr(0, w - 1)) + "~";
  const std::string pad(w - text.size(), ' ');
  return right_aligned ? pad + std::string(text) : std::string(text) + pad;
}

std::vector<Part> FitParts(const std::vector<Part>& parts, int width, std::string_view separator) {
  std::vector<std::size_t> order(parts.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return parts[a].priority < parts[b].priority; });
  std::vector<std::optional<std::string>> kept(parts.size());
  std::size_t used = 0, count = 0;
  const std::size_t limit = width > 0 ? static_cast<std::size_t>(width) : SIZE_MAX;
  for (const std::size_t i : order) {
    const Part& part = parts[i];
    if (part.text.empty()) continue;
    const std::size_t sep = count == 0 ? 0 : separator.size();
    if (used + sep + part.text.size() <= limit) {
      kept[i] = part.text;
    } else if (part.cuttable && used + sep + kMinCut <= limit) {
      kept[i] = FitLine(part.text, static_cast<int>(limit - used - sep));
    } else {
      continue;
    }
    used += sep + kept[i]->size();
    ++count;
  }
  std::vector<Part> out;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (!kept[i]) continue;
    Part part = parts[i];
    part.text = *kept[i];
    out.push_back(std::move(part));
  }
  return out;
}

std::string JoinParts(const std::vector<Part>& parts, bool color, std::string_view separator) {
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (i > 0) out += separator;
    const bool paint = color && parts[i].color != nullptr && *parts[i].color != '\0';
    if (paint) out += parts[i].color;
    out += parts[i].text;
    if (paint) out += "\x1b[0m";
  }
  return out;
}

}  // namespace canfleet::tools
