#pragma once
/// @file What the product fault tests share (valve-12in12out, encoder-dual-valve,
/// power-supply-24v-350w under `canfleet up`, issues 16, 17, 19): a fleet started from the test's
/// topology, and the observations a CANopen master makes of a product node, each through the real
/// `canfleet` CLI: its NMT state (from its heartbeat), the EMCYs the orchestrator's master port
/// records (status and the orchestrator's log line `name: EMCY xxxxh, ...`), SDO reads, and the
/// simulated outputs (`canfleet io get`). Every wait is a generous bound, never a timed claim.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tests/system/fleet/fleet_harness.hpp"

namespace canfleet::system_test {

/// Bound on anything that should follow a fault or a command (real time, a loaded machine).
inline constexpr std::chrono::seconds kProductPatience{30};

/// How long a test watches that a node keeps its NMT state and outputs after a fault (the topologies
/// give every node a 200 ms heartbeat), and why that is long enough.
inline constexpr std::chrono::milliseconds kNoChangeWindow{1500};
inline constexpr const char* kNoChangeReason =
    "7 heartbeat periods (200 ms) after the reaction was due: an NMT change shows in the next heartbeat, an "
    "output reaction at the next tick";

class ProductFleetTest : public ::testing::Test {
 protected:
  /// Starts `canfleet up` on `topology`, waits until every node of `operational` reports
  /// operational, then until a heartbeat of `producer` was seen after that (CiA 301
  /// §7.2.8.3.2.2: a consumer starts at the first heartbeat it receives after 1016h was written,
  /// so a heartbeat the orchestrator sees after its consumers were started reached them too).
  void StartFleet(const std::string& topology, const std::vector<std::string>& operational,
                  const std::string& producer);

  FleetUnderTest& fleet() { return *fleet_; }

  /// `canfleet ARGS...`; false (with a test failure saying why) when it did not succeed.
  bool Cli(const std::vector<std::string>& args);
  /// "operational", "pre-operational", "stopped", "unknown"; "" when the orchestrator did not answer.
  std::string NmtOf(const std::string& node) const;
  bool WaitNmt(const std::string& node, const std::string& state) const;
  /// The last EMCY code the orchestrator saw from `node`; nullopt when none.
  std::optional<std::uint32_t> LastEmcyOf(const std::string& node) const;
  std::uint64_t EmcyCountOf(const std::string& node) const;
  /// Waits until the orchestrator's log has `text` (its EMCY lines witness every EMCY, also one
  /// that status' last_emcy no longer shows because a later one followed).
  bool WaitLog(const std::string& text) const;
  /// The orchestrator's EMCY log line for `node` (fleet.cpp): code, error register, 5 data bytes.
  static std::string EmcyLine(const std::string& node, std::uint16_t code, std::uint8_t reg,
                              const std::string& data);
  /// The family's record of a communication error on `node` (family_error_policy.hpp): the
  /// orchestrator logged its EMCY `code` with 1001h = 01h and the manufacturer bytes `data`, 1003h
  /// sub 1 holds `entry` and 1001h reads 01h.
  void ExpectErrorRecorded(const std::string& node, std::uint16_t code, const std::string& data,
                           std::uint32_t entry);
  /// SDO upload through the orchestrator; nullopt (with a test failure) when it aborts.
  std::optional<std::uint64_t> Sdo(const std::string& node, const std::string& index, int sub,
                                   const std::string& type) const;
  /// A simulated output as a number (the value text's leading number), NaN when unreadable.
  double IoNumber(const std::string& node, const std::string& name) const;
  /// A simulated output's text ("" when unreadable).
  std::string IoText(const std::string& node, const std::string& name) const;
  /// `name` of `node` reads `value` now (within 0.5 of it).
  bool Reads(const std::string& node, const std::string& name, double value) const;
  /// Waits until `name` of `node` reads `value` (within 0.5 of it).
  bool WaitIo(const std::string& node, const std::string& name, double value) const;
  /// Proves that something does not change: `condition` holds during the whole `window`, a bounded
  /// observation whose `reason` says why it is long enough (CONTRIBUTING "Tests"). False at the
  /// first poll where it does not hold.
  bool HoldsFor(const std::function<bool()>& condition, std::chrono::milliseconds window,
                const char* reason) const;

 private:
  std::unique_ptr<FleetUnderTest> fleet_;
};

}  // namespace canfleet::system_test
