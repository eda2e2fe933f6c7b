#include "orchestrator/topology/topology_warning.hpp"

#include <cmath>
#include <cstdio>
#include <vector>

namespace canfleet::topology {

std::string TopologyWarning::Message() const {
  std::string out = file;
  if (line > 0) out += ":" + std::to_string(line) + ":" + std::to_string(column);
  out += ": warning: ";
  if (!field.empty()) out += field + ": ";
  return out + reason;
}

std::string PercentText(double fraction) {
  const double percent = fraction * 100.0;
  char text[32];
  if (percent > 0 && percent < 9.95)
    std::snprintf(text, sizeof text, "%.1f %%", percent);
  else
    std::snprintf(text, sizeof text, "%.0f %%", std::round(percent));
  return text;
}

namespace {

std::string BitrateText(std::uint32_t bitrate) {
  if (bitrate % 1000 == 0) return std::to_string(bitrate / 1000) + " kbit/s";
  char text[32];
  std::snprintf(text, sizeof text, "%.3f kbit/s", bitrate / 1000.0);
  return text;
}

}  // namespace

std::string BusLoad::Describe() const {
  std::string out = PercentText(Total()) + " of " + BitrateText(bitrate);
  std::vector<std::string> parts;
  if (tpdos > 0) parts.push_back("TPDOs " + PercentText(tpdos));
  if (heartbeats > 0) parts.push_back("heartbeats " + PercentText(heartbeats));
  if (sync > 0) parts.push_back("SYNC " + PercentText(sync));
  if (!parts.empty()) {
    out += " (";
    for (std::size_t i = 0; i < parts.size(); ++i)
      out += (i ? ", " : "") + parts[i];
    out += ")";
  }
  return out;
}

}  // namespace canfleet::topology
