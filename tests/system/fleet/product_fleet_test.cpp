#include "tests/system/fleet/product_fleet_test.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

namespace canfleet::system_test {

void ProductFleetTest::StartFleet(const std::string& topology, const std::vector<std::string>& operational,
                                  const std::string& producer) {
  fleet_ = std::make_unique<FleetUnderTest>(topology);
  ASSERT_TRUE(fleet_->WaitReady()) << fleet_->Log();
  for (const auto& node : operational)
    ASSERT_TRUE(WaitNmt(node, "operational")) << node << "\n" << fleet_->Log();
  const auto since = std::chrono::steady_clock::now();
  ASSERT_TRUE(WaitUntil(
      [&] {
        const auto status = fleet_->Status();
        const auto* p = fleet_->Node(status, producer);
        const double elapsed_s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
        return p->heartbeat_age_s() >= 0 && p->heartbeat_age_s() < elapsed_s;
      },
      kProductPatience));
}

bool ProductFleetTest::Cli(const std::vector<std::string>& args) {
  const auto result = fleet_->Cli(args);
  EXPECT_EQ(result.exit_code, 0) << "canfleet " << args.front() << ": " << result.err;
  return result.exit_code == 0;
}

std::string ProductFleetTest::NmtOf(const std::string& node) const {
  const auto status = fleet_->Status();
  return fleet_->Node(status, node)->nmt_state();
}

bool ProductFleetTest::WaitNmt(const std::string& node, const std::string& state) const {
  return WaitUntil([&] { return NmtOf(node) == state; }, kProductPatience);
}

std::optional<std::uint32_t> ProductFleetTest::LastEmcyOf(const std::string& node) const {
  const auto status = fleet_->Status();
  const auto* n = fleet_->Node(status, node);
  if (!n->has_last_emcy()) return std::nullopt;
  return n->last_emcy().code();
}

std::uint64_t ProductFleetTest::EmcyCountOf(const std::string& node) const {
  const auto status = fleet_->Status();
  return fleet_->Node(status, node)->emcy_count();
}

bool ProductFleetTest::WaitLog(const std::string& text) const {
  return WaitUntil([&] { return fleet_->Log().find(text) != std::string::npos; }, kProductPatience);
}

std::string ProductFleetTest::EmcyLine(const std::string& node, std::uint16_t code, std::uint8_t reg,
                                       const std::string& data) {
  char head[64];
  std::snprintf(head, sizeof head, ": EMCY %04Xh, error register %02Xh, data ", static_cast<unsigned>(code),
                static_cast<unsigned>(reg));
  return node + head + data;
}

std::optional<std::uint64_t> ProductFleetTest::Sdo(const std::string& node, const std::string& index, int sub,
                                                   const std::string& type) const {
  std::string error;
  auto value = fleet_->SdoReadUnsigned(node, index, sub, type, &error);
  if (!value) ADD_FAILURE() << "sdo read " << node << " " << index << " " << sub << ": " << error;
  return value;
}

double ProductFleetTest::IoNumber(const std::string& node, const std::string& name) const {
  const auto text = fleet_->IoGet(node, name);
  if (!text) return std::numeric_limits<double>::quiet_NaN();
  try {
    return std::stod(*text);
  } catch (const std::exception&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
}

void ProductFleetTest::ExpectErrorRecorded(const std::string& node, std::uint16_t code,
                                           const std::string& data, std::uint32_t entry) {
  EXPECT_TRUE(WaitLog(EmcyLine(node, code, 0x01, data))) << fleet().Log();
  EXPECT_EQ(Sdo(node, "0x1003", 1, "u32"), entry) << node;
  EXPECT_EQ(Sdo(node, "0x1001", 0, "u8"), 0x01u) << node;
}

std::string ProductFleetTest::IoText(const std::string& node, const std::string& name) const {
  return fleet_->IoGet(node, name).value_or("");
}

bool ProductFleetTest::Reads(const std::string& node, const std::string& name, double value) const {
  return std::fabs(IoNumber(node, name) - value) < 0.5;
}

bool ProductFleetTest::WaitIo(const std::string& node, const std::string& name, double value) const {
  return WaitUntil([&] { return Reads(node, name, value); }, kProductPatience);
}

bool ProductFleetTest::HoldsFor(const std::function<bool()>& condition, std::chrono::milliseconds window,
                                const char* reason) const {
  EXPECT_NE(std::string(reason), "") << "state why the window is long enough";
  const auto end = std::chrono::steady_clock::now() + window;
  do {
    if (!condition()) return false;
  } while (std::chrono::steady_clock::now() < end);
  return true;
}

}  // namespace canfleet::system_test
