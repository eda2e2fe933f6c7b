#pragma once
/// @file The `canfleet top` screen: which rows, in which order, and how they are drawn (plain ANSI).
/// Pure functions of a FleetView, so tests check them without DDS or a terminal.

#include <chrono>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tools/telemetry/fleet_view.hpp"

namespace canfleet::tools {

enum class SortKey { kBusNode, kName, kState, kErrors, kLastChange, kDevice };
const char* ToString(SortKey key);
std::optional<SortKey> ParseSortKey(std::string_view text);
/// The next key in the order above (the `s` key cycles through them).
SortKey NextSortKey(SortKey key);

struct TopFilter {
  std::string bus{};  ///< exact bus name; empty = all
  /// NMT state ("operational", "pre-operational", "stopped", "initialising", "unknown";
  /// case-insensitive), controller state ("error-active", "error-passive", "bus-off"), or "fault"
  /// (IsFaulted) / "ok"; empty = all. The short words of old ("OPER", "PREOP", "STOP", "INIT",
  /// "active", "passive") still work.
  std::string state{};
  std::string text{};  ///< case-insensitive substring of "bus #id name device"; empty = all
};

/// True if the filter's `state` is one of the accepted words (for command-line validation).
bool IsValidStateFilter(std::string_view state);
bool Matches(const NodeRow& row, const TopFilter& filter, WallTime now);

/// Rows that pass `filter`, ordered by `key` (ties by bus then node-id).
std::vector<const NodeRow*> SelectRows(const FleetView& view, const TopFilter& filter, SortKey key,
                                       bool reverse, WallTime now);

struct RenderSettings {
  TopFilter filter{};
  SortKey sort = SortKey::kBusNode;
  bool reverse = false;
  int width = 132;
  int height = 50;  ///< whole screen, header and footer included
  int page = 0;     ///< clamped to the last page
  bool color = true;
  std::chrono::seconds highlight{5};  ///< how long changes and EMCYs stay highlighted
  int event_lines = 5;                ///< recent events shown under the table
  std::string filter_prompt{};        ///< shown when the user is typing a filter
  WallTime now{};
  /// The node the arrow keys selected (marked in the table); unset: none.
  std::optional<NodeKey> selected{};
  /// Show the selected node's detail screen instead of the table (Enter; Esc goes back).
  bool detail = false;
};

/// Node rows that fit on one page of a screen of `height` lines with `status_lines` bus and
/// scenario lines above the table.
int RowsPerPage(const RenderSettings& settings, int status_lines);
/// The bus and scenario lines RenderFrame shows for `view` under `filter`.
int StatusLines(const FleetView& view, const TopFilter& filter);
int PageCount(std::size_t rows, int rows_per_page);

/// The whole screen as text, lines separated by '\n', no cursor movement (the caller clears): the
/// title, a line per bus and per scenario (its cycle, clock, verdict counts and step), the node
/// table and the recent events (verdicts among them), or with `detail` and a selected node that
/// node's detail screen (RenderNodeDetail). Every line fits `width`: the table shows the columns
/// that fit, by priority (at 80: name, bus, id, NMT, controller, TEC/REC, error register,
/// heartbeat consumers, last EMCY, age), other lines keep their most important parts or are cut
/// at a word boundary with "...". The selected row starts with "> " (and is in reverse video in
/// color).
std::string RenderFrame(const FleetView& view, const RenderSettings& settings);

/// The row `delta` rows after (or before) `current` among `rows`, held at the ends; the first row
/// when nothing is selected or the selected node is no longer shown; unset when `rows` is empty.
std::optional<NodeKey> MoveSelection(const std::vector<const NodeRow*>& rows,
                                     const std::optional<NodeKey>& current, int delta);
/// The page (0-based) on which `key` is shown, if it is.
std::optional<int> PageOf(const std::vector<const NodeRow*>& rows, const NodeKey& key, int rows_per_page);

/// "1:02:03" or "3d04h".
std::string FormatUptime(std::chrono::milliseconds uptime);
/// "0.4s", "12s", "5m", "3h".
std::string FormatAge(std::chrono::system_clock::duration age);

}  // namespace canfleet::tools
