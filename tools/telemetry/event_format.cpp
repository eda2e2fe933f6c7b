#include "tools/telemetry/event_format.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <utility>

namespace canfleet::tools {

const char* DescribeEmcyCode(std::uint16_t code) {
  // CiA 301 table 21: the code's class is given by its high byte(s); look up the exact code first,
  // then xx00h, then x000h.
  static constexpr std::array<std::pair<std::uint16_t, const char*>, 37> kCodes{{
      {0x0000, "error reset or no error"},
      {0x1000, "generic error"},
      {0x2000, "current"},
      {0x2100, "current, device input side"},
      {0x2200, "current inside the device"},
      {0x2300, "current, device output side"},
      {0x3000, "voltage"},
      {0x3100, "mains voltage"},
      {0x3200, "voltage inside the device"},
      {0x3300, "output voltage"},
      {0x4000, "temperature"},
      {0x4100, "ambient temperature"},
      {0x4200, "device temperature"},
      {0x5000, "device hardware"},
      {0x6000, "device software"},
      {0x6100, "internal software"},
      {0x6200, "user software"},
      {0x6300, "data set"},
      {0x7000, "additional modules"},
      {0x8000, "monitoring"},
      {0x8100, "communication"},
      {0x8110, "CAN overrun (objects lost)"},
      {0x8120, "CAN in error passive mode"},
      {0x8130, "life guard error or heartbeat error"},
      {0x8140, "recovered from bus off"},
      {0x8150, "CAN-ID collision"},
      {0x8200, "protocol error"},
      {0x8210, "PDO not processed due to length error"},
      {0x8220, "PDO length exceeded"},
      {0x8230, "DAM MPDO not processed, destination object not available"},
      {0x8240, "unexpected SYNC data length"},
      {0x8250, "RPDO timeout"},
      {0x9000, "external error"},
      {0xF000, "additional functions"},
      {0xFF00, "device specific"},
      {0xFF01, "device specific"},
      {0xFFFF, "device specific"},
  }};
  for (const std::uint16_t candidate :
       {code, static_cast<std::uint16_t>(code & 0xFF00u), static_cast<std::uint16_t>(code & 0xF000u)}) {
    for (const auto& [value, text] : kCodes) {
      if (value == candidate) return text;
    }
  }
  return code >= 0xFF00 ? "device specific" : "unknown";
}

std::string FormatTime(WallTime time) {
  const auto since_epoch = time.time_since_epoch();
  const auto seconds = std::chrono::floor<std::chrono::seconds>(since_epoch);
  const auto millis = std::chrono::duration_cast<std::chrono::milliseconds>(since_epoch - seconds).count();
  const std::time_t t = static_cast<std::time_t>(seconds.count());
  std::tm utc{};
  gmtime_r(&t, &utc);
  char text[64];
  std::snprintf(text, sizeof text, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", utc.tm_year + 1900, utc.tm_mon + 1,
                utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec, static_cast<int>(millis));
  return text;
}

std::string FormatTimeOfDay(WallTime time) {
  const std::string full = FormatTime(time);  // "2024-05-01T12:00:01.234Z"
  return full.size() >= 23 ? full.substr(11, 12) : full;
}

std::string JsonString(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char escaped[8];
          std::snprintf(escaped, sizeof escaped, "\\u%04x",
                        static_cast<unsigned>(static_cast<unsigned char>(c)));
          out += escaped;
        } else {
          out += c;
        }
    }
  }
  out += '"';
  return out;
}

namespace {

std::string Printf(const char* format, auto... args) {
  char text[256];
  std::snprintf(text, sizeof text, format, args...);
  return text;
}

std::string NodeLabel(const FleetEvent& e) {
  if (e.node_id == 0) return e.bus;
  return e.bus + " #" + std::to_string(e.node_id) + (e.name.empty() ? "" : " " + e.name);
}

/// The part of a verdict's result line after "<name>: ": what was expected and what was seen.
std::string_view VerdictDetail(const VerdictSample& v) {
  const std::string_view text = v.text;
  const std::string key = "  " + v.name + ": ";
  const std::size_t at = text.find(key);
  return at == std::string_view::npos ? text : text.substr(at + key.size());
}

std::string VerdictText(const VerdictSample& v, bool compact) {
  if (!compact)
    return (v.scenario.empty() ? std::string("scenario") : v.scenario) + " VERDICT cycle " +
           std::to_string(v.cycle) + ": " + v.text;
  return std::string(telemetry::ToString(v.result)) + " " + v.name + " (cycle " + std::to_string(v.cycle) +
         "): " + std::string(VerdictDetail(v));
}

}  // namespace

std::string FormatEventText(const FleetEvent& e, bool compact) {
  const std::string time = compact ? FormatTimeOfDay(e.time) : FormatTime(e.time);
  if (e.kind == EventKind::kVerdict) {
    std::string line = time + " " + (e.verdict ? VerdictText(*e.verdict, compact) : "VERDICT ?");
    if (e.replay) line += " [history]";
    return line;
  }
  std::string line = time + " " + NodeLabel(e) + " ";
  switch (e.kind) {
    case EventKind::kEmcy: {
      const auto& m = e.emcy->emcy;
      line += Printf("EMCY %04Xh reg=%02Xh mfr=%02X %02X %02X %02X %02X (%s)", m.code, m.error_register,
                     m.manufacturer[0], m.manufacturer[1], m.manufacturer[2], m.manufacturer[3],
                     m.manufacturer[4], DescribeEmcyCode(m.code));
      break;
    }
    case EventKind::kFault: {
      const auto& f = *e.fault;
      line += Printf("FAULT %s #%u %s", telemetry::ToString(f.action), f.fault_id, f.kind.c_str());
      for (const auto& [name, value] : f.parameters)
        line += " " + name + "=" + value;
      break;
    }
    case EventKind::kHeartbeatConsumer:
      line += Printf("HB-CONSUMER node %u: %s -> %s", e.peer_node, e.from.c_str(), e.to.c_str());
      break;
    case EventKind::kNodeSeen:
      line += e.from.empty() ? "SEEN " + e.to : "BACK " + e.to;
      break;
    case EventKind::kNodeGone:
      line += "GONE (" + e.to + ")";
      break;
    case EventKind::kNmt:
      line += "NMT " + e.from + " -> " + e.to;
      break;
    case EventKind::kController:
      line += "CONTROLLER " + e.from + " -> " + e.to;
      break;
    case EventKind::kErrorRegister:
      line += "ERROR-REGISTER " + e.from + " -> " + e.to;
      break;
    case EventKind::kVerdict:
      break;
  }
  if (e.replay) line += " [history]";
  return line;
}

std::string FormatEventJson(const FleetEvent& e) {
  std::string json = "{\"time\":" + JsonString(FormatTime(e.time)) +
                     ",\"type\":" + JsonString(ToString(e.kind)) + ",\"bus\":" + JsonString(e.bus) +
                     ",\"node\":" + std::to_string(e.node_id);
  if (!e.name.empty()) json += ",\"name\":" + JsonString(e.name);
  switch (e.kind) {
    case EventKind::kEmcy: {
      const auto& m = e.emcy->emcy;
      json += ",\"code\":" + std::to_string(m.code) +
              ",\"error_register\":" + std::to_string(m.error_register) + ",\"manufacturer\":[";
      for (std::size_t i = 0; i < m.manufacturer.size(); ++i) {
        json += (i ? "," : "") + std::to_string(m.manufacturer[i]);
      }
      json += "],\"bus_time_ns\":" + std::to_string(m.bus_time.count()) +
              ",\"text\":" + JsonString(DescribeEmcyCode(m.code));
      break;
    }
    case EventKind::kFault: {
      const auto& f = *e.fault;
      json += ",\"fault_id\":" + std::to_string(f.fault_id) +
              ",\"action\":" + JsonString(telemetry::ToString(f.action)) + ",\"kind\":" + JsonString(f.kind) +
              ",\"target_node\":" + std::to_string(f.target_node) + ",\"parameters\":{";
      for (std::size_t i = 0; i < f.parameters.size(); ++i) {
        json += (i ? "," : "") + JsonString(f.parameters[i].first) + ":" + JsonString(f.parameters[i].second);
      }
      json += "},\"bus_time_ns\":" + std::to_string(f.bus_time.count());
      break;
    }
    case EventKind::kVerdict: {
      if (!e.verdict) break;
      const auto& v = *e.verdict;
      char time[40];
      std::snprintf(time, sizeof time, "%.3f", v.scenario_time_s);
      json += ",\"source\":" + JsonString(v.source) + ",\"index\":" + std::to_string(v.index) +
              ",\"scenario\":" + JsonString(v.scenario) + ",\"cycle\":" + std::to_string(v.cycle) +
              ",\"result\":" + JsonString(telemetry::ToString(v.result)) + ",\"name\":" + JsonString(v.name) +
              ",\"line\":" + std::to_string(v.line) + ",\"text\":" + JsonString(v.text) +
              ",\"text_cut\":" + (v.text_cut ? "true" : "false") +
              ",\"scenario_time_s\":" + (std::isfinite(v.scenario_time_s) ? std::string(time) : "null");
      break;
    }
    case EventKind::kHeartbeatConsumer:
      json += ",\"peer\":" + std::to_string(e.peer_node) + ",\"from\":" + JsonString(e.from) +
              ",\"to\":" + JsonString(e.to);
      break;
    default:
      json += ",\"from\":" + JsonString(e.from) + ",\"to\":" + JsonString(e.to);
      break;
  }
  json += std::string(",\"replay\":") + (e.replay ? "true" : "false") + "}";
  return json;
}

}  // namespace canfleet::tools
