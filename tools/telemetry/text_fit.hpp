#pragma once
/// @file Fitting text into a terminal's width without cutting a word silently: lines cut at a word
/// boundary end in "...", table cells cut short end in "~", and a line of parts (the title, a bus
/// line, the scenario line) keeps its most important parts when the width is short.

#include <string>
#include <string_view>
#include <vector>

namespace canfleet::tools {

/// `text` if it has at most `width` characters, else cut at a word boundary and ending in "..."
/// (telemetry::CutAtWord). ASCII text (escapes are added after fitting).
std::string FitLine(std::string_view text, int width);

/// `text` padded or cut to exactly `width` characters; a cut one ends in "~" (a table cell).
std::string FitCell(std::string_view text, int width, bool right_aligned = false);

/// One part of a line.
struct Part {
  std::string text;
  int priority = 0;        ///< lower is more important: kept first when the width is short
  bool cuttable = false;   ///< when it does not fit whole: cut at a word boundary (FitLine) to what is left
  const char* color = "";  ///< ANSI code it is painted in (with color on)
};

/// The parts that fit in `width`, in their order, chosen by priority: each part, most important
/// first, is kept if it fits with the parts already kept (separated by `separator`); a cuttable
/// one is cut to the room left (if at least 12 characters are). Returns the parts kept (their text
/// possibly cut).
std::vector<Part> FitParts(const std::vector<Part>& parts, int width, std::string_view separator = "  ");

/// The parts joined by `separator`; each painted in its color (and reset) when `color`.
std::string JoinParts(const std::vector<Part>& parts, bool color, std::string_view separator = "  ");

}  // namespace canfleet::tools
