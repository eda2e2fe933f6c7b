#include "web/web_state.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>

#include "tools/telemetry/event_format.hpp"

namespace canfleet::web {

using tools::JsonString;

namespace {

std::string Number(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string Seconds(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

std::string Hex(std::uint32_t v, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%0*X", digits, v);
  return buf;
}

void IoJson(std::ostringstream& out, const std::vector<telemetry::IoValueSample>& values) {
  out << '[';
  for (std::size_t i = 0; i < values.size(); ++i) {
    const auto& v = values[i];
    out << (i ? "," : "") << "{\"name\":" << JsonString(v.name) << ",\"value\":" << Number(v.value)
        << ",\"unit\":" << JsonString(v.unit) << ",\"text\":" << JsonString(v.text) << '}';
  }
  out << ']';
}

void NodeSummaryJson(std::ostringstream& out, const tools::NodeRow& row, tools::WallTime now) {
  const auto& s = row.status;
  out << "{\"key\":" << JsonString(s.bus + ":" + std::to_string(int{s.node_id}))
      << ",\"bus\":" << JsonString(s.bus) << ",\"id\":" << int{s.node_id}
      << ",\"name\":" << JsonString(s.name) << ",\"device\":" << JsonString(s.device)
      << ",\"nmt\":" << JsonString(telemetry::StateName(s.nmt_state))
      << ",\"controller\":" << JsonString(telemetry::StateName(s.controller_state)) << ",\"tec\":" << s.tec
      << ",\"rec\":" << int{s.rec} << ",\"error_register\":" << JsonString(Hex(s.error_register, 2))
      << ",\"heartbeat_ms\":" << s.heartbeat_producer_ms
      << ",\"last_sample\":" << Seconds(EpochSeconds(row.last_sample))
      << ",\"alive\":" << (row.alive ? "true" : "false")
      << ",\"stale\":" << (tools::IsStale(row, now) ? "true" : "false")
      << ",\"faulted\":" << (tools::IsFaulted(row, now) ? "true" : "false") << ",\"last_emcy\":";
  if (s.last_emcy)
    out << "{\"code\":" << JsonString(Hex(s.last_emcy->code, 4))
        << ",\"register\":" << JsonString(Hex(s.last_emcy->error_register, 2)) << '}';
  else
    out << "null";
  out << '}';
}

void NodeDetailJson(std::ostringstream& out, const tools::NodeRow& row, tools::WallTime now) {
  const auto& s = row.status;
  out << "{\"summary\":";
  NodeSummaryJson(out, row, now);
  out << ",\"uptime_s\":" << Seconds(std::chrono::duration<double>(s.uptime).count())
      << ",\"rpdo\":" << s.rpdo_count << ",\"tpdo\":" << s.tpdo_count << ",\"consumers\":[";
  for (std::size_t i = 0; i < s.heartbeat_consumers.size(); ++i) {
    const auto& c = s.heartbeat_consumers[i];
    out << (i ? "," : "") << "{\"node\":" << int{c.node_id} << ",\"time_ms\":" << c.time_ms
        << ",\"state\":" << JsonString(telemetry::ToString(c.state)) << '}';
  }
  out << "],\"emcy\":[";
  for (std::size_t i = 0; i < row.emcy_history.size(); ++i) {
    const auto& e = row.emcy_history[i];
    std::string data;
    for (const std::uint8_t b : e.sample.emcy.manufacturer)
      data += (data.empty() ? "" : " ") + Hex(b, 2);
    out << (i ? "," : "") << "{\"time\":" << Seconds(EpochSeconds(e.time))
        << ",\"code\":" << JsonString(Hex(e.sample.emcy.code, 4))
        << ",\"register\":" << JsonString(Hex(e.sample.emcy.error_register, 2))
        << ",\"data\":" << JsonString(data) << '}';
  }
  out << "],\"inputs\":";
  IoJson(out, row.io ? row.io->inputs : std::vector<telemetry::IoValueSample>{});
  out << ",\"outputs\":";
  IoJson(out, row.io ? row.io->outputs : std::vector<telemetry::IoValueSample>{});
  out << '}';
}

void BusJson(std::ostringstream& out, const std::string& name, const tools::BusRow& row) {
  out << "{\"name\":" << JsonString(name);
  if (const auto& s = row.stats) {
    out << ",\"bitrate\":" << s->bitrate << ",\"mode\":" << JsonString(s->mode)
        << ",\"load\":" << Number(s->load_percent) << ",\"fps\":" << Number(s->frames_per_second)
        << ",\"frames\":" << s->frames_total << ",\"error_frames\":" << s->error_frames
        << ",\"nodes\":" << s->node_count << ",\"simulated_s\":" << Seconds(s->simulated_s)
        << ",\"factor\":" << Number(s->speed_factor);
  }
  out << ",\"faults\":[";
  bool first = true;
  for (const auto& [id, f] : row.active_faults) {
    out << (first ? "" : ",") << "{\"id\":" << id << ",\"kind\":" << JsonString(f.kind)
        << ",\"node\":" << int{f.target_node} << ",\"parameters\":{";
    for (std::size_t i = 0; i < f.parameters.size(); ++i)
      out << (i ? "," : "") << JsonString(f.parameters[i].first) << ':' << JsonString(f.parameters[i].second);
    out << "}}";
    first = false;
  }
  out << "]}";
}

void ScenarioJson(std::ostringstream& out, const tools::ScenarioRow& row) {
  const auto& s = row.status;
  out << "{\"source\":" << JsonString(s.source) << ",\"scenario\":" << JsonString(s.scenario)
      << ",\"time_mode\":" << JsonString(s.time_mode) << ",\"time_s\":" << Seconds(s.scenario_time_s)
      << ",\"cycle\":" << s.cycle << ",\"running\":" << (s.running ? "true" : "false")
      << ",\"alive\":" << (row.alive ? "true" : "false") << ",\"expectations\":" << s.expectations
      << ",\"passed\":" << s.passed << ",\"failed\":" << s.failed << ",\"skipped\":" << s.skipped
      << ",\"pending\":" << s.pending << ",\"step\":" << JsonString(s.step) << '}';
}

}  // namespace

std::string ValidUtf8(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  std::size_t i = 0;
  while (i < text.size()) {
    const auto c = static_cast<unsigned char>(text[i]);
    std::size_t len = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    bool ok = len > 0 && i + len <= text.size();
    for (std::size_t k = 1; ok && k < len; ++k)
      ok = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
    if (ok && len > 1) {  // no overlong forms, surrogates or code points beyond U+10FFFF
      const auto c1 = static_cast<unsigned char>(text[i + 1]);
      ok = !(len == 2 && c < 0xC2) && !(len == 3 && c == 0xE0 && c1 < 0xA0) &&
           !(len == 3 && c == 0xED && c1 >= 0xA0) && !(len == 4 && c == 0xF0 && c1 < 0x90) &&
           !(len == 4 && (c > 0xF4 || (c == 0xF4 && c1 >= 0x90)));
    }
    if (ok) {
      out.append(text.substr(i, len));
      i += len;
    } else {
      out += "\xEF\xBF\xBD";  // U+FFFD
      ++i;
    }
  }
  return out;
}

double EpochSeconds(tools::WallTime t) {
  return std::chrono::duration<double>(t.time_since_epoch()).count();
}

WebState::WebState(tools::WallTime started, WebStateOptions options)
    : options_(options), view_(started, 200) {}

void WebState::Record(std::vector<tools::FleetEvent>& events) {
  for (const auto& e : events)
    events_.push_back({next_event_++, e.time, tools::FormatEventJson(e)});
  while (events_.size() > options_.max_events)
    events_.pop_front();
  events.clear();
}

void WebState::AddPoint(tools::WallTime time, double simulated_s, std::string series, double value) {
  if (!series_names_.contains(series)) series_names_.insert(series);
  points_.push_back({next_point_++, time, simulated_s, std::move(series), value});
}

void WebState::Apply(const telemetry::NodeStatusSample& s, const telemetry::SampleMeta& m) {
  std::lock_guard lock(mutex_);
  view_.Apply(s, m, &scratch_);
  Record(scratch_);
  if (!m.valid_data) return;
  // The controller's state over time (0 error-active, 1 error-passive, 2 bus-off) and its counters.
  const std::string prefix = "node:" + s.bus + ":" + std::to_string(int{s.node_id}) + "/";
  const auto sim = simulated_.find(s.bus);
  const double simulated = sim == simulated_.end() ? -1 : sim->second;
  // Kept when they change only: a status comes every second from every node, and these rarely move.
  for (const auto& [name, value] :
       {std::pair{"controller", static_cast<double>(s.controller_state)},
        std::pair{"TEC", static_cast<double>(s.tec)}, std::pair{"REC", static_cast<double>(s.rec)}}) {
    std::string series = prefix + name;
    const auto last = last_value_.find(series);
    if (last != last_value_.end() && last->second == value) continue;
    last_value_[series] = value;
    AddPoint(m.source_time, simulated, std::move(series), value);
  }
}

void WebState::Apply(const telemetry::EmcySample& s, const telemetry::SampleMeta& m) {
  std::lock_guard lock(mutex_);
  view_.Apply(s, m, &scratch_);
  Record(scratch_);
}

void WebState::Apply(const telemetry::IoSnapshotSample& s, const telemetry::SampleMeta& m) {
  std::lock_guard lock(mutex_);
  view_.Apply(s, m, &scratch_);
  Record(scratch_);
  if (!m.valid_data) return;
  const std::string prefix = "io:" + s.bus + ":" + std::to_string(int{s.node_id}) + "/";
  const auto sim = simulated_.find(s.bus);
  const double simulated = sim == simulated_.end() ? -1 : sim->second;
  for (const auto* values : {&s.inputs, &s.outputs})
    for (const auto& v : *values)
      AddPoint(m.source_time, simulated, prefix + v.name, v.value);
}

void WebState::Apply(const telemetry::BusStatsSample& s, const telemetry::SampleMeta& m) {
  std::lock_guard lock(mutex_);
  view_.Apply(s, m, &scratch_);
  Record(scratch_);
  if (!m.valid_data) return;
  const double simulated = s.mode == "virtual" ? s.simulated_s : -1;
  if (simulated >= 0) simulated_[s.bus] = simulated;
  const std::string prefix = "bus:" + s.bus + "/";
  AddPoint(m.source_time, simulated, prefix + "load", s.load_percent);
  AddPoint(m.source_time, simulated, prefix + "fps", s.frames_per_second);
  AddPoint(m.source_time, simulated, prefix + "error_frames", static_cast<double>(s.error_frames));
}

void WebState::Apply(const telemetry::FaultEventSample& s, const telemetry::SampleMeta& m) {
  std::lock_guard lock(mutex_);
  view_.Apply(s, m, &scratch_);
  Record(scratch_);
}

void WebState::Apply(const telemetry::VerdictSample& s, const telemetry::SampleMeta& m) {
  std::lock_guard lock(mutex_);
  view_.Apply(s, m, &scratch_);
  Record(scratch_);
}

void WebState::Apply(const telemetry::ScenarioStatusSample& s, const telemetry::SampleMeta& m) {
  std::lock_guard lock(mutex_);
  view_.Apply(s, m, &scratch_);
  Record(scratch_);
}

void WebState::Frame(const std::string& bus, const CanFrame& frame, std::int64_t time_ns) {
  std::lock_guard lock(mutex_);
  diag_.Frame(bus, frame, time_ns);
}

void WebState::Trim(tools::WallTime now) {
  std::lock_guard lock(mutex_);
  const auto oldest = now - options_.retention;
  while (!points_.empty() && points_.front().time < oldest)
    points_.pop_front();
  while (!events_.empty() && events_.front().time < oldest)
    events_.pop_front();
}

std::vector<std::string> WebState::BusNames() const {
  std::lock_guard lock(mutex_);
  std::set<std::string> names;
  for (const auto& [name, row] : view_.buses())
    names.insert(name);
  for (const auto& [key, row] : view_.nodes())
    names.insert(key.bus);
  return {names.begin(), names.end()};
}

std::size_t WebState::EventCount() const {
  std::lock_guard lock(mutex_);
  return events_.size();
}

std::size_t WebState::PointCount() const {
  std::lock_guard lock(mutex_);
  return points_.size();
}

std::string WebState::NodeJson(const std::string& bus, std::uint8_t node_id, tools::WallTime now) const {
  std::lock_guard lock(mutex_);
  const auto it = view_.nodes().find({bus, node_id});
  if (it == view_.nodes().end()) return "null";
  std::ostringstream out;
  NodeDetailJson(out, it->second, now);
  std::string json = out.str();
  const NodeDiag* diag = diag_.Find(bus, node_id);
  json.insert(json.size() - 1, ",\"diag\":" + (diag ? DiagStats::Json(*diag) : std::string("null")));
  return ValidUtf8(json);
}

std::string WebState::UpdateJson(Cursor& cursor, tools::WallTime now) const {
  std::lock_guard lock(mutex_);
  std::ostringstream out;
  out << "{\"type\":\"update\",\"now\":" << Seconds(EpochSeconds(now))
      << ",\"retention_s\":" << options_.retention.count() << ",\"nodes\":[";
  bool first = true;
  for (const auto& [key, row] : view_.nodes()) {
    std::ostringstream node;
    NodeSummaryJson(node, row, now);
    const std::string json = node.str();
    const std::size_t hash = std::hash<std::string>{}(json);
    auto& sent = cursor.node_hashes[key.bus + ":" + std::to_string(int{key.node_id})];
    if (sent == hash) continue;
    sent = hash;
    out << (first ? "" : ",") << json;
    first = false;
  }
  out << "],\"buses\":[";
  first = true;
  for (const auto& [name, row] : view_.buses()) {
    if (!first) out << ',';
    BusJson(out, name, row);
    first = false;
  }
  out << "],\"scenarios\":[";
  first = true;
  for (const auto& [source, row] : view_.scenarios()) {
    if (!first) out << ',';
    ScenarioJson(out, row);
    first = false;
  }
  out << "],\"events\":[";
  first = true;
  for (const auto& e : events_) {
    if (e.seq <= cursor.event_seq) continue;
    out << (first ? "" : ",") << e.json;
    first = false;
    cursor.event_seq = e.seq;
  }
  out << "],\"points\":[";
  first = true;
  for (const auto& p : points_) {
    const bool fresh = p.seq > cursor.point_seq;
    const bool wanted = p.series.starts_with("bus:") || cursor.plotted.contains(p.series);
    if (!wanted || !(fresh || cursor.backfill.contains(p.series))) continue;
    out << (first ? "" : ",") << '[' << Seconds(EpochSeconds(p.time)) << ',' << JsonString(p.series) << ','
        << Number(p.value) << ',' << Seconds(p.simulated_s) << ']';
    first = false;
  }
  if (!points_.empty()) cursor.point_seq = points_.back().seq;
  cursor.backfill.clear();
  out << ']';
  if (now - cursor.diag_sent >= std::chrono::seconds(1)) {
    cursor.diag_sent = now;
    out << ",\"diag\":{";
    first = true;
    for (const auto& [key, row] : view_.nodes()) {
      const NodeDiag* diag = diag_.Find(key.bus, key.node_id);
      if (diag == nullptr) continue;
      const std::string json = DiagStats::Json(*diag);
      const std::string name = key.bus + ":" + std::to_string(int{key.node_id});
      auto& sent = cursor.diag_hashes[name];
      const std::size_t hash = std::hash<std::string>{}(json);
      if (sent == hash) continue;
      sent = hash;
      out << (first ? "" : ",") << JsonString(name) << ':' << json;
      first = false;
    }
    out << '}';
  }
  if (series_names_.size() != cursor.series_sent) {
    cursor.series_sent = series_names_.size();
    out << ",\"series\":[";
    first = true;
    for (const auto& name : series_names_) {
      out << (first ? "" : ",") << JsonString(name);
      first = false;
    }
    out << ']';
  }
  out << '}';
  // A WebSocket text message must be UTF-8 (RFC 6455 §5.6), else the browser drops the connection;
  // a publisher's strings are whatever it sent.
  return ValidUtf8(out.str());
}

}  // namespace canfleet::web
