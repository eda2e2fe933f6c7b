#include "telemetry/samples.hpp"

#include <algorithm>

namespace canfleet::telemetry {

const char* ToString(HeartbeatConsumerState state) {
  switch (state) {
    case HeartbeatConsumerState::kUnknown:
      return "unknown";
    case HeartbeatConsumerState::kActive:
      return "active";
    case HeartbeatConsumerState::kTimedOut:
      return "timed-out";
  }
  return "?";
}

const char* ToString(FaultAction action) {
  return action == FaultAction::kInjected ? "injected" : "cleared";
}

const char* ToString(VerdictResult result) {
  switch (result) {
    case VerdictResult::kPass:
      return "pass";
    case VerdictResult::kFail:
      return "FAIL";
    case VerdictResult::kSkip:
      return "skip";
    case VerdictResult::kError:
      return "error";
  }
  return "?";
}

const char* StateName(std::optional<NmtState> state) {
  return state ? canopen::ToString(*state) : "unknown";
}

const char* StateName(ControllerState state) {
  return canfleet::ToString(state);
}

std::size_t CutAtWord(std::string_view text, std::size_t max) {
  if (text.size() <= max) return text.size();
  if (max <= kCutMarker.size()) return 0;
  const std::size_t room = max - kCutMarker.size();
  // The last space at or before `room` (a cut right before a space keeps the word whole).
  std::size_t cut = room;
  while (cut > 0 && text[cut] != ' ')
    --cut;
  while (cut > 0 && text[cut - 1] == ' ')  // no trailing blanks before the marker
    --cut;
  return cut == 0 ? room : cut;  // one word longer than the room: cut it (the marker says so)
}

canfleet_telemetry_NmtState ToDds(std::optional<NmtState> state) {
  if (!state) return canfleet_telemetry_NMT_UNKNOWN;
  switch (*state) {
    case NmtState::kInitialising:
      return canfleet_telemetry_NMT_INITIALISING;
    case NmtState::kStopped:
      return canfleet_telemetry_NMT_STOPPED;
    case NmtState::kOperational:
      return canfleet_telemetry_NMT_OPERATIONAL;
    case NmtState::kPreOperational:
      return canfleet_telemetry_NMT_PRE_OPERATIONAL;
  }
  return canfleet_telemetry_NMT_UNKNOWN;
}

std::optional<NmtState> FromDds(canfleet_telemetry_NmtState state) {
  return NmtStateFromRaw(state);
}

std::optional<NmtState> NmtStateFromRaw(std::int32_t state) {
  switch (state) {
    case canfleet_telemetry_NMT_UNKNOWN:
      return std::nullopt;
    case canfleet_telemetry_NMT_INITIALISING:
      return NmtState::kInitialising;
    case canfleet_telemetry_NMT_STOPPED:
      return NmtState::kStopped;
    case canfleet_telemetry_NMT_OPERATIONAL:
      return NmtState::kOperational;
    case canfleet_telemetry_NMT_PRE_OPERATIONAL:
      return NmtState::kPreOperational;
  }
  return std::nullopt;
}

canfleet_telemetry_ControllerState ToDds(ControllerState state) {
  switch (state) {
    case ControllerState::kErrorActive:
      return canfleet_telemetry_CONTROLLER_ERROR_ACTIVE;
    case ControllerState::kErrorPassive:
      return canfleet_telemetry_CONTROLLER_ERROR_PASSIVE;
    case ControllerState::kBusOff:
      return canfleet_telemetry_CONTROLLER_BUS_OFF;
  }
  return canfleet_telemetry_CONTROLLER_ERROR_ACTIVE;
}

ControllerState FromDds(canfleet_telemetry_ControllerState state) {
  return ControllerStateFromRaw(state);
}

ControllerState ControllerStateFromRaw(std::int32_t state) {
  switch (state) {
    case canfleet_telemetry_CONTROLLER_ERROR_ACTIVE:
      return ControllerState::kErrorActive;
    case canfleet_telemetry_CONTROLLER_ERROR_PASSIVE:
      return ControllerState::kErrorPassive;
    case canfleet_telemetry_CONTROLLER_BUS_OFF:
      return ControllerState::kBusOff;
  }
  return ControllerState::kErrorActive;
}

canfleet_telemetry_HeartbeatConsumerState ToDds(HeartbeatConsumerState state) {
  switch (state) {
    case HeartbeatConsumerState::kUnknown:
      return canfleet_telemetry_HB_CONSUMER_UNKNOWN;
    case HeartbeatConsumerState::kActive:
      return canfleet_telemetry_HB_CONSUMER_ACTIVE;
    case HeartbeatConsumerState::kTimedOut:
      return canfleet_telemetry_HB_CONSUMER_TIMED_OUT;
  }
  return canfleet_telemetry_HB_CONSUMER_UNKNOWN;
}

HeartbeatConsumerState FromDds(canfleet_telemetry_HeartbeatConsumerState state) {
  return HeartbeatConsumerStateFromRaw(state);
}

HeartbeatConsumerState HeartbeatConsumerStateFromRaw(std::int32_t state) {
  switch (state) {
    case canfleet_telemetry_HB_CONSUMER_UNKNOWN:
      return HeartbeatConsumerState::kUnknown;
    case canfleet_telemetry_HB_CONSUMER_ACTIVE:
      return HeartbeatConsumerState::kActive;
    case canfleet_telemetry_HB_CONSUMER_TIMED_OUT:
      return HeartbeatConsumerState::kTimedOut;
  }
  return HeartbeatConsumerState::kUnknown;
}

canfleet_telemetry_FaultAction ToDds(FaultAction action) {
  return action == FaultAction::kInjected ? canfleet_telemetry_FAULT_INJECTED
                                          : canfleet_telemetry_FAULT_CLEARED;
}

FaultAction FromDds(canfleet_telemetry_FaultAction action) {
  return FaultActionFromRaw(action);
}

FaultAction FaultActionFromRaw(std::int32_t action) {
  return action == canfleet_telemetry_FAULT_CLEARED ? FaultAction::kCleared : FaultAction::kInjected;
}

canfleet_telemetry_VerdictResult ToDds(VerdictResult result) {
  switch (result) {
    case VerdictResult::kPass:
      return canfleet_telemetry_VERDICT_PASS;
    case VerdictResult::kFail:
      return canfleet_telemetry_VERDICT_FAIL;
    case VerdictResult::kSkip:
      return canfleet_telemetry_VERDICT_SKIP;
    case VerdictResult::kError:
      return canfleet_telemetry_VERDICT_ERROR;
  }
  return canfleet_telemetry_VERDICT_ERROR;
}

VerdictResult FromDds(canfleet_telemetry_VerdictResult result) {
  return VerdictResultFromRaw(result);
}

VerdictResult VerdictResultFromRaw(std::int32_t result) {
  switch (result) {
    case canfleet_telemetry_VERDICT_PASS:
      return VerdictResult::kPass;
    case canfleet_telemetry_VERDICT_FAIL:
      return VerdictResult::kFail;
    case canfleet_telemetry_VERDICT_SKIP:
      return VerdictResult::kSkip;
    case canfleet_telemetry_VERDICT_ERROR:
      return VerdictResult::kError;
  }
  return VerdictResult::kError;  // an unknown value from a hostile or newer writer
}

namespace {

// A sequence's _length is trusted only up to its IDL bound (Cyclone checks it on receipt; this
// keeps a locally built sample from reading past its buffer too).
template <typename Seq>
std::uint32_t BoundedLength(const Seq& seq, std::size_t bound) {
  return static_cast<std::uint32_t>(
      std::min<std::size_t>({seq._length, bound, seq._buffer ? seq._length : 0}));
}

EmcyInfo ToEmcyInfo(std::uint16_t code, std::uint8_t error_register, const std::uint8_t* manufacturer,
                    std::uint64_t bus_time_ns) {
  EmcyInfo info;
  info.code = code;
  info.error_register = error_register;
  if (manufacturer) std::copy_n(manufacturer, info.manufacturer.size(), info.manufacturer.begin());
  info.bus_time = BusTime(static_cast<BusTime::rep>(bus_time_ns));
  return info;
}

IoValueSample FromDds(const canfleet_telemetry_IoValue& value) {
  return {FromBounded(value.name), value.value, FromBounded(value.unit), FromBounded(value.text)};
}

}  // namespace

NodeStatusSample FromDds(const canfleet_telemetry_NodeStatus& s) {
  NodeStatusSample out;
  out.bus = FromBounded(s.bus);
  out.node_id = s.node_id;
  out.device = FromBounded(s.device);
  out.name = FromBounded(s.name);
  out.nmt_state = NmtStateFromRaw(RawEnum(s.nmt_state));
  out.error_register = s.error_register;
  out.controller_state = ControllerStateFromRaw(RawEnum(s.controller_state));
  out.tec = s.tec;
  out.rec = s.rec;
  out.heartbeat_producer_ms = s.heartbeat_producer_ms;
  const std::uint32_t n = BoundedLength(s.heartbeat_consumers, kMaxHeartbeatConsumers);
  out.heartbeat_consumers.reserve(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const auto& c = s.heartbeat_consumers._buffer[i];
    out.heartbeat_consumers.push_back({c.node_id, c.time_ms, HeartbeatConsumerStateFromRaw(RawEnum(c.state)),
                                       NmtStateFromRaw(RawEnum(c.last_state))});
  }
  out.rpdo_count = s.rpdo_count;
  out.tpdo_count = s.tpdo_count;
  out.uptime = std::chrono::milliseconds(s.uptime_ms);
  if (s.last_emcy.valid) {
    out.last_emcy =
        ToEmcyInfo(s.last_emcy.code, s.last_emcy.error_register, nullptr, s.last_emcy.bus_time_ns);
  }
  out.publish_period = std::chrono::milliseconds(s.publish_period_ms);
  out.serial = s.serial;
  return out;
}

EmcySample FromDds(const canfleet_telemetry_Emcy& s) {
  return {FromBounded(s.bus), s.node_id, ToEmcyInfo(s.code, s.error_register, s.manufacturer, s.bus_time_ns),
          s.serial};
}

IoSnapshotSample FromDds(const canfleet_telemetry_IoSnapshot& s) {
  IoSnapshotSample out;
  out.bus = FromBounded(s.bus);
  out.node_id = s.node_id;
  for (std::uint32_t i = 0; i < BoundedLength(s.inputs, kMaxIoChannels); ++i) {
    out.inputs.push_back(FromDds(s.inputs._buffer[i]));
  }
  for (std::uint32_t i = 0; i < BoundedLength(s.outputs, kMaxIoChannels); ++i) {
    out.outputs.push_back(FromDds(s.outputs._buffer[i]));
  }
  out.serial = s.serial;
  return out;
}

BusStatsSample FromDds(const canfleet_telemetry_BusStats& s) {
  BusStatsSample out;
  out.bus = FromBounded(s.bus);
  out.bitrate = s.bitrate;
  out.mode = FromBounded(s.mode);
  out.load_percent = s.load_percent;
  out.frames_per_second = s.frames_per_second;
  out.frames_total = s.frames_total;
  out.error_frames = s.error_frames;
  out.node_count = s.node_count;
  for (std::uint32_t i = 0; i < BoundedLength(s.top_cob_ids, kMaxTopCobIds); ++i) {
    out.top_cob_ids.push_back({s.top_cob_ids._buffer[i].cob_id, s.top_cob_ids._buffer[i].frames_per_second});
  }
  out.serial = s.serial;
  out.simulated_s = s.simulated_s;
  out.speed_factor = s.speed_factor;
  return out;
}

FaultEventSample FromDds(const canfleet_telemetry_FaultEvent& s) {
  FaultEventSample out;
  out.bus = FromBounded(s.bus);
  out.fault_id = s.fault_id;
  out.action = FaultActionFromRaw(RawEnum(s.action));
  out.kind = FromBounded(s.kind);
  out.target_node = s.target_node;
  for (std::uint32_t i = 0; i < BoundedLength(s.parameters, kMaxFaultParameters); ++i) {
    out.parameters.emplace_back(FromBounded(s.parameters._buffer[i].name),
                                FromBounded(s.parameters._buffer[i].value));
  }
  out.bus_time = BusTime(static_cast<BusTime::rep>(s.bus_time_ns));
  out.serial = s.serial;
  return out;
}

VerdictSample FromDds(const canfleet_telemetry_Verdict& s) {
  VerdictSample out;
  out.source = FromBounded(s.source);
  out.index = s.index;
  out.scenario = FromBounded(s.scenario);
  out.cycle = s.cycle;
  out.result = VerdictResultFromRaw(RawEnum(s.result));
  out.name = FromBounded(s.name);
  out.line = s.line;
  out.text = FromBounded(s.text);
  out.text_cut = s.text_cut;
  out.scenario_time_s = s.scenario_time_s;
  out.serial = s.serial;
  return out;
}

ScenarioStatusSample FromDds(const canfleet_telemetry_ScenarioStatus& s) {
  ScenarioStatusSample out;
  out.source = FromBounded(s.source);
  out.scenario = FromBounded(s.scenario);
  out.time_mode = FromBounded(s.time_mode);
  out.scenario_time_s = s.scenario_time_s;
  out.cycle = s.cycle;
  out.running = s.running;
  out.expectations = s.expectations;
  out.passed = s.passed;
  out.failed = s.failed;
  out.skipped = s.skipped;
  out.pending = s.pending;
  out.step = FromBounded(s.step);
  out.step_time_s = s.step_time_s;
  out.publish_period = std::chrono::milliseconds(s.publish_period_ms);
  out.serial = s.serial;
  return out;
}

}  // namespace canfleet::telemetry
