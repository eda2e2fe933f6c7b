#pragma once
/// @file What the browser view shows, built from the fleet's telemetry (the topics `canfleet top`
/// reads, through the same FleetView): nodes, buses, scenarios, the fleet-wide timeline of events,
/// and time series (bus statistics, simulated I/O signals) kept for a retention window. Serialised
/// as JSON for the page: a full snapshot, then per client only what is new. No DDS and no clock of
/// its own: tests feed it samples with their times.
///
/// Threading: one mutex; the telemetry thread applies samples, the server's thread reads.

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "tools/telemetry/fleet_view.hpp"
#include "web/diag_stats.hpp"

namespace canfleet::web {

struct WebStateOptions {
  /// Time series and timeline older than this (source time) are dropped: it bounds memory.
  std::chrono::seconds retention{600};
  /// Timeline events kept at most (the oldest go first).
  std::size_t max_events = 5000;
};

/// Where one client stands: what it has been sent already, and which series it plots.
struct Cursor {
  std::uint64_t event_seq = 0;  ///< events up to this sequence number were sent
  std::uint64_t point_seq = 0;  ///< series points up to this sequence number were sent
  /// Each node's summary as last sent (by "bus:id"): a node is sent again only when it changed.
  std::map<std::string, std::size_t> node_hashes;
  std::size_t series_sent = 0;  ///< how many series names were known when the list was last sent
  /// Signal series the client plots ("io:can0:5/IN1.voltage_mV"): only their points are sent (bus
  /// statistics always). Names added since the last update get every point still kept.
  std::set<std::string> plotted;
  std::set<std::string> backfill;
  /// Each node's statistics as last sent; they go at most once a second, and only what changed.
  std::map<std::string, std::size_t> diag_hashes;
  tools::WallTime diag_sent{};
};

class WebState {
 public:
  explicit WebState(tools::WallTime started, WebStateOptions options = {});

  void Apply(const telemetry::NodeStatusSample& s, const telemetry::SampleMeta& m);
  void Apply(const telemetry::EmcySample& s, const telemetry::SampleMeta& m);
  void Apply(const telemetry::IoSnapshotSample& s, const telemetry::SampleMeta& m);
  void Apply(const telemetry::BusStatsSample& s, const telemetry::SampleMeta& m);
  void Apply(const telemetry::FaultEventSample& s, const telemetry::SampleMeta& m);
  void Apply(const telemetry::VerdictSample& s, const telemetry::SampleMeta& m);
  void Apply(const telemetry::ScenarioStatusSample& s, const telemetry::SampleMeta& m);
  /// A frame a bus monitor saw (`canfleet web --broker`): CANopen-Diag statistics (diag_stats.hpp).
  void Frame(const std::string& bus, const CanFrame& frame, std::int64_t time_ns);

  /// One JSON message for a client at `cursor` (advanced to now): {"type":"update", "now",
  /// "nodes": [the summaries that changed], "buses", "scenarios" (whole: they are few), "events":
  /// [new], "points": [new, of bus statistics and the plotted series], "series": [every series
  /// name, when there are new ones]}. The first (a zero cursor) carries everything still kept.
  std::string UpdateJson(Cursor& cursor, tools::WallTime now) const;
  /// One node in full (the page's node view): its summary, simulated I/O with units, EMCY history,
  /// heartbeat consumers. "null" for a node nobody published.
  std::string NodeJson(const std::string& bus, std::uint8_t node_id, tools::WallTime now) const;

  /// Drops what is older than the retention window before `now`.
  void Trim(tools::WallTime now);

  /// Every bus the telemetry named (statistics or a node on it).
  std::vector<std::string> BusNames() const;
  std::size_t EventCount() const;
  std::size_t PointCount() const;

 private:
  /// One value of a series at a time: bus statistics ("bus:can0/load"), a signal
  /// ("io:can0:5/IN1.voltage_mV").
  struct Point {
    std::uint64_t seq = 0;
    tools::WallTime time{};
    double simulated_s = -1;  ///< the bus's simulated time, in virtual time; -1 otherwise
    std::string series;
    double value = 0;
  };
  struct Event {
    std::uint64_t seq = 0;
    tools::WallTime time{};
    std::string json;  ///< tools::FormatEventJson
  };
  void Record(std::vector<tools::FleetEvent>& events);
  void AddPoint(tools::WallTime time, double simulated_s, std::string series, double value);

  mutable std::mutex mutex_;
  WebStateOptions options_;
  tools::FleetView view_;
  std::deque<Event> events_;
  std::deque<Point> points_;
  std::uint64_t next_event_ = 1;
  std::uint64_t next_point_ = 1;
  std::vector<tools::FleetEvent> scratch_;
  /// The latest simulated time each bus reported (virtual time), for the page's clock.
  std::map<std::string, double> simulated_;
  std::set<std::string> series_names_;  ///< every series seen (the page's picker)
  DiagStats diag_;
  std::map<std::string, double> last_value_;  ///< series kept on change only: their last value
};

/// `text` with every byte that is not part of valid UTF-8 replaced by U+FFFD.
std::string ValidUtf8(std::string_view text);

/// Seconds since the Unix epoch, as the page's time axis counts.
double EpochSeconds(tools::WallTime t);

}  // namespace canfleet::web
