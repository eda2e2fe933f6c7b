// The Quad's dictionary table (node/devices/quad_controller/quad-controller.od) against the EDS it
// replaced: data/quad-controller-handwritten.eds is the hand-written EDS of stop 13, kept as the
// witness that converting the Quad to a table changed no object, default, limit or file fact.
#include <gtest/gtest.h>

#include "node/canopen/eds/eds.hpp"
#include "node/devices/dictionary/od_table.hpp"
#include "node/devices/quad_controller/quad_controller.hpp"

namespace canfleet::devices {
namespace {

TEST(QuadTable, DescribesExactlyTheHandWrittenEds) {
  const canopen::EdsFile table = ReadOdTable(CANFLEET_QUAD_TABLE);
  const canopen::EdsFile handwritten = canopen::ReadEds(CANFLEET_QUAD_HANDWRITTEN_EDS);
  const auto differences = canopen::DiffEdsFiles(table, handwritten, canopen::EdsFormat::kEds);
  std::string listed;
  for (const auto& d : differences)
    listed += d + "\n";
  EXPECT_TRUE(differences.empty()) << listed;
}

// The build compiles the EDS generated from the table into the node.
TEST(QuadTable, TheNodeRunsOnTheGeneratedEds) {
  const canopen::EdsFile compiled = canopen::ParseEds(QuadControllerEds().Text(), "quad-controller.eds");
  const canopen::EdsFile table = ReadOdTable(CANFLEET_QUAD_TABLE);
  EXPECT_TRUE(canopen::DiffEdsFiles(compiled, table, canopen::EdsFormat::kEds).empty());
}

}  // namespace
}  // namespace canfleet::devices
