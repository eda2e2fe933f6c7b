#include "orchestrator/fleet/external_adoption.hpp"

#include <spdlog/spdlog.h>

namespace canfleet::fleet {

ExternalAdoption::ExternalAdoption(Context context, std::vector<Port> ports)
    : context_(std::move(context)), timer_(context_.scheduler, [this] { Check(); }) {
  for (auto& port : ports)
    watches_.push_back({std::move(port), std::nullopt, std::nullopt});
}

void ExternalAdoption::Start() {
  if (!watches_.empty()) timer_.StartAfter(kCheckPeriod);
}

void ExternalAdoption::Check() {
  const TimePoint now = context_.scheduler.Now();
  for (auto& watch : watches_) {
    const Port& port = watch.port;
    if (!context_.attached(port.bus, port.name)) {
      watch.attached_since.reset();
      watch.last_reset.reset();
      continue;
    }
    if (context_.booted(port.bus, port.node_id)) continue;
    if (!watch.attached_since) watch.attached_since = now;
    if (now - *watch.attached_since < kGrace) continue;
    if (watch.last_reset && now - *watch.last_reset < kRetry) continue;
    spdlog::info(
        "{}: attached to {} without a boot-up (it kept running while the orchestrator was "
        "away): NMT reset communication to node-ID {}, so that it boots up and is configured",
        port.name, port.bus, static_cast<int>(port.node_id));
    watch.last_reset = now;
    context_.reset_communication(port);
  }
  timer_.StartAfter(kCheckPeriod);
}

}  // namespace canfleet::fleet
