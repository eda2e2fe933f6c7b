#pragma once
/// @file The identifiers a node's port listens to (wire::Acceptance: its acceptance filter, as a CAN
/// controller's hardware filter). The session delivers only those frames, and the time conductor
/// grants a node process no further than a frame it listens to could reach it (grant_horizon.hpp).

#include <algorithm>
#include <bitset>
#include <cstdint>
#include <span>
#include <vector>

#include "bus/can_frame.hpp"
#include "clock/scheduler.hpp"

namespace canfleet::transport {

class Acceptance {
 public:
  /// An identifier whose frames, when a heartbeat producer's confined timer sends them, make the
  /// node send nothing before `delay` after they arrive (a heartbeat consumer only re-arms its
  /// timeout: wire::Acceptance.passive).
  struct Passive {
    std::uint32_t id = 0;
    Duration delay{};
  };

  /// Every frame (`all`), or the 11-bit identifiers `ids` (others above 0x7FF are ignored), of
  /// which `passive` ones answer nothing at once.
  void Set(bool all, std::span<const std::uint32_t> ids, std::span<const Passive> passive = {}) {
    all_ = all;
    bits_.reset();
    ids_.clear();
    delays_.clear();
    for (const std::uint32_t id : ids)
      if (id <= 0x7FF) bits_.set(id);
    for (std::uint32_t id = 0; id <= 0x7FF; ++id) {
      if (!bits_.test(id)) continue;
      ids_.push_back(id);
      Duration delay{};
      for (const Passive& p : passive)
        if (p.id == id) delay = p.delay;
      delays_.push_back(delay);
    }
  }

  bool All() const { return all_; }
  /// Listens to nothing: no frame can wake it.
  bool Empty() const { return !all_ && ids_.empty(); }
  /// The 11-bit identifiers listened to, ascending (without All()).
  std::span<const std::uint32_t> Ids() const { return ids_; }
  /// For each of Ids(): how long after a heartbeat on it arrives the node may send at the
  /// earliest (0: at once).
  std::span<const Duration> Delays() const { return delays_; }
  /// The same for one key (0 when not listened to, or All()).
  Duration DelayOf(std::uint32_t key) const {
    const auto it = std::lower_bound(ids_.begin(), ids_.end(), key);
    return it != ids_.end() && *it == key ? delays_[static_cast<std::size_t>(it - ids_.begin())] : Duration{};
  }
  /// Extended and error frames always pass (the filter is for 11-bit identifiers).
  bool Accepts(const CanFrame& frame) const {
    return all_ || frame.extended() || frame.error() || bits_.test(frame.id & 0x7FF);
  }
  /// `key`: an 11-bit identifier, or kExtendedKey for any 29-bit frame.
  bool AcceptsKey(std::uint32_t key) const { return all_ || key > 0x7FF || bits_.test(key); }

  /// Stands for every 29-bit identifier in the keys of grant_horizon.hpp.
  static constexpr std::uint32_t kExtendedKey = 0x800;
  static std::uint32_t KeyOf(const CanFrame& frame) {
    return frame.extended() || frame.error() ? kExtendedKey : frame.id & 0x7FF;
  }

 private:
  bool all_ = true;  // until the node sends its filter: every frame
  std::bitset<2048> bits_;
  std::vector<std::uint32_t> ids_;
  std::vector<Duration> delays_;
};

}  // namespace canfleet::transport
