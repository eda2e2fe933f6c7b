#pragma once
// Shared by the DDS tests of this binary: every test gets the loopback configuration and a domain
// of its own (ctest runs tests in parallel, each in its own process), plus a bounded wait.

#include <chrono>
#include <functional>
#include <thread>

#include "telemetry/dds.hpp"

namespace canfleet::telemetry::testing {

/// Domains 60..: unit tests; the system test uses others. Participants in different domains
/// never see each other, so parallel test processes cannot disturb one another.
inline DdsOptions TestDds(std::uint32_t domain) {
  return {.domain_id = 60 + domain, .config_file = CANFLEET_DDS_LOOPBACK_CONFIG};
}

/// Polls `condition` until true or `timeout` (generous: DDS runs on real time).
inline bool Eventually(const std::function<bool()>& condition,
                       std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return condition();
}

}  // namespace canfleet::telemetry::testing
