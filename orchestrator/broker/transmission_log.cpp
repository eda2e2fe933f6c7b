#include "orchestrator/broker/transmission_log.hpp"

#include <algorithm>
#include <unordered_map>

namespace canfleet::broker::detail {

void TransmissionLog::Summarize(BusTime now, BusTime window, BusTime created,
                                const std::optional<Ongoing>& ongoing, std::size_t top_n,
                                BusStats& stats) const {
  BusTime from = std::max(now - window, created);
  const std::size_t count = wrapped_ ? records_.size() : next_;
  if (wrapped_ && count > 0) {
    // The oldest record still held: the window cannot reach further back than it.
    const Entry& oldest = records_[next_];
    from = std::max(from, oldest.start);
  }

  BusTime busy{};
  std::uint64_t frames = 0, errors = 0;
  std::unordered_map<std::uint64_t, std::uint64_t> per_id;
  // Newest first, stopping at the first transfer that ended before the range.
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t i = (next_ + records_.size() - 1 - k) % records_.size();
    const Entry& e = records_[i];
    // A transfer counts when it ends inside (from, now]; an unpaced record (no duration) also
    // counts when it lies exactly on `from`, so traffic at the bus's creation time is not lost.
    const bool inside = e.end > from || (e.end == from && e.start == e.end);
    if (!inside) break;
    busy += std::min(e.end, now) - std::max(e.start, from);
    if (e.error) {
      ++errors;
    } else {
      ++frames;
      ++per_id[std::uint64_t{e.id} << 1 | (e.extended ? 1U : 0U)];
    }
  }
  if (ongoing && ongoing->start < now) busy += std::min(ongoing->end, now) - std::max(ongoing->start, from);

  const BusTime covered = now - from;
  stats.window = covered;
  if (covered <= BusTime::zero()) return;
  const double seconds = std::chrono::duration<double>(covered).count();
  stats.load_percent = 100.0 * static_cast<double>(busy.count()) / static_cast<double>(covered.count());
  stats.frames_per_s = static_cast<double>(frames) / seconds;
  stats.error_frames_per_s = static_cast<double>(errors) / seconds;

  std::vector<CobIdStats> ids;
  ids.reserve(per_id.size());
  for (const auto& [key, n] : per_id)
    ids.push_back(
        {static_cast<std::uint32_t>(key >> 1), (key & 1U) != 0, n, static_cast<double>(n) / seconds});
  std::sort(ids.begin(), ids.end(), [](const CobIdStats& a, const CobIdStats& b) {
    if (a.frames != b.frames) return a.frames > b.frames;
    if (a.extended != b.extended) return !a.extended;
    return a.id < b.id;
  });
  if (ids.size() > top_n) ids.resize(top_n);
  stats.top_ids = std::move(ids);
}

}  // namespace canfleet::broker::detail
