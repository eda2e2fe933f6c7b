#pragma once
/// @file Suggestions for a name nobody declared: the nearest valid names by edit distance, for the
/// messages of every layer that refuses a name (a signal on a node, a node in the fleet, a device
/// in the catalog, a field of a topology file): "no signal IN9.voltage_mV on quad-5; nearest:
/// IN1.voltage_mV, IN2.voltage_mV".

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace canfleet {

/// Levenshtein distance (insertions, deletions, substitutions; letters compared without case).
std::size_t EditDistance(std::string_view a, std::string_view b);

/// Up to `max` of `candidates` nearest to `name`, nearest first (ties keep the candidates' order),
/// leaving out those so far that they would not help: more than a third of the longer name, and
/// at least 2 edits, away. Empty when nothing is near.
std::vector<std::string> NearestNames(std::string_view name, const std::vector<std::string>& candidates,
                                      std::size_t max = 3);

/// "a, b, c" (empty for none).
std::string JoinNames(const std::vector<std::string>& names, std::string_view separator = ", ");

}  // namespace canfleet
