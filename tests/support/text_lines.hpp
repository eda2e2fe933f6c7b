#pragma once
/// @file A program's or a formatter's output as its lines, for tests that compare them one by one.

#include <string>
#include <vector>

namespace canfleet::test {

/// `text` split at '\n' (no line terminators kept; a last line without '\n' counts).
std::vector<std::string> Lines(const std::string& text);

}  // namespace canfleet::test
