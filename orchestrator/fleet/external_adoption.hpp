#pragma once
/// @file Adopting external nodes that are already running. The master configures a node after
/// its boot-up (CiA 302), but an external node that kept running while the orchestrator
/// restarted reconnects to the new broker without one, and would never be configured or counted
/// as ready. ExternalAdoption notices such a node (attached, no boot-up seen after a grace time)
/// and sends it NMT reset communication (CiA 301 §7.2.8.3.1.5): the node resets its communication
/// objects and sends its boot-up, and the normal configuration follows. Application objects keep
/// their values (reset communication, not reset node).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "clock/scheduler.hpp"

namespace canfleet::fleet {

class ExternalAdoption {
 public:
  /// One CAN port of an external node.
  struct Port {
    std::string name;  ///< the node's name, as it attaches to the broker
    std::string bus;
    std::uint8_t node_id = 0;
  };
  struct Context {
    Scheduler& scheduler;
    std::function<bool(const std::string& bus, const std::string& name)> attached;
    std::function<bool(const std::string& bus, std::uint8_t node_id)> booted;
    std::function<void(const Port& port)> reset_communication;
  };

  /// A node that boots up normally sends its boot-up within milliseconds of attaching.
  static constexpr Duration kGrace = std::chrono::seconds(1);
  /// If the reset was lost (or the node ignored it), ask again this much later.
  static constexpr Duration kRetry = std::chrono::seconds(5);
  static constexpr Duration kCheckPeriod = std::chrono::milliseconds(250);

  ExternalAdoption(Context context, std::vector<Port> ports);

  /// Starts the periodic check (nothing to do without external ports).
  void Start();

 private:
  struct Watch {
    Port port;
    std::optional<TimePoint> attached_since;
    std::optional<TimePoint> last_reset;
  };
  void Check();

  Context context_;
  std::vector<Watch> watches_;
  Timer timer_;
};

}  // namespace canfleet::fleet
