#pragma once
// Helpers shared by the EDS tests: fixture paths, parsing inline text, and checking where an
// EdsError points.

#include <gtest/gtest.h>

#include <string>
#include <string_view>

#include "node/canopen/eds/eds_error.hpp"
#include "node/canopen/eds/eds_reader.hpp"

namespace canfleet::canopen::test {

inline std::string DataPath(std::string_view name) {
  return std::string(CANFLEET_EDS_TEST_DATA) + "/" + std::string(name);
}

/// Where an error must point and a piece of its detail.
struct ExpectedError {
  std::size_t line;
  std::string section;
  std::string key;
  std::string detail;
};

/// Parses `text` as "test.eds" and checks that it fails with an EdsError naming the file, the
/// line, the section and the key, both in its accessors and in what().
inline void ExpectEdsError(std::string_view text, const ExpectedError& expected) {
  try {
    ParseEds(text, "test.eds");
    ADD_FAILURE() << "no EdsError; expected line " << expected.line << " [" << expected.section << "] "
                  << expected.key << ": " << expected.detail;
  } catch (const EdsError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.file(), "test.eds") << what;
    EXPECT_EQ(e.line(), expected.line) << what;
    EXPECT_EQ(e.section(), expected.section) << what;
    EXPECT_EQ(e.key(), expected.key) << what;
    EXPECT_NE(e.detail().find(expected.detail), std::string::npos) << what;
    std::string prefix = "test.eds:" + std::to_string(expected.line) + ": ";
    if (!expected.section.empty()) prefix += "[" + expected.section + "] ";
    if (!expected.key.empty()) prefix += expected.key + ": ";
    EXPECT_EQ(what.rfind(prefix, 0), 0u) << what << "\nexpected prefix: " << prefix;
  }
}

}  // namespace canfleet::canopen::test
