#include "clock/granted_scheduler.hpp"

namespace canfleet {

void GrantedScheduler::AdvanceTo(TimePoint t) {
  if (t < Now()) t = Now();
  RunDue(t, [this](TimePoint deadline) {
    if (deadline > Now()) Set(deadline);
  });
  Set(t);
}

}  // namespace canfleet
