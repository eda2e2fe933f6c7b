#include "node/devices/shared_objects.hpp"

namespace canfleet::devices {

using canopen::Origin;
using canopen::SdoAbort;
using canopen::SubObject;

SharedObjects::SharedObjects(canopen::ObjectDictionary& primary, canopen::ObjectDictionary& replica,
                             std::uint16_t first, std::uint16_t last)
    : primary_(primary), replica_(replica) {
  auto& objects = primary.objects();
  for (auto it = objects.lower_bound(first); it != objects.end() && it->first <= last; ++it) {
    canopen::Object* other = replica.Find(it->first);
    if (!other) continue;
    for (auto& [sub_index, sub] : it->second.subs) {
      auto match = other->subs.find(sub_index);
      if (match == other->subs.end() || match->second.type != sub.type) continue;
      Share(sub, match->second);
    }
  }
}

SubObject* SharedObjects::ReplicaOf(const SubObject& primary_sub) const {
  auto it = pairs_.find(&primary_sub);
  return it == pairs_.end() ? nullptr : it->second;
}

// Writing only when the values differ ends the echo: primary → replica → (equal) stop.
void SharedObjects::Copy(canopen::ObjectDictionary& to_od, SubObject& to, const SubObject& from) {
  if (to.value == from.value) return;
  to_od.Write(to, from.value, Origin::kDevice);
}

void SharedObjects::Share(SubObject& primary, SubObject& replica) {
  pairs_.emplace(&primary, &replica);
  replica.value = primary.value;
  primary.listeners.push_back([this, &replica](SubObject& sub, Origin) { Copy(replica_, replica, sub); });
  replica.listeners.push_back([this, &primary](SubObject& sub, Origin) { Copy(primary_, primary, sub); });
  // The primary's validators are looked up at call time, so hooks installed after sharing count.
  replica.validators.push_back(
      [&primary](const SubObject&, std::span<const std::uint8_t> data, Origin origin) {
        for (auto& validate : primary.validators) {
          if (auto rc = validate(primary, data, origin); rc != SdoAbort::kNone) return rc;
        }
        return SdoAbort::kNone;
      });
  replica.read_hooks.push_back([&primary](SubObject& sub, Origin origin) {
    for (auto& hook : primary.read_hooks) {
      if (auto rc = hook(primary, origin); rc != SdoAbort::kNone) return rc;
    }
    sub.value = primary.value;
    return SdoAbort::kNone;
  });
}

}  // namespace canfleet::devices
