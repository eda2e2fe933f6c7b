#include "telemetry/node_telemetry.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>

#include "telemetry/samples.hpp"
#include "telemetry/topics.hpp"

namespace canfleet::telemetry {

bool StatusChanged(const NodeStatusSnapshot& a, const NodeStatusSnapshot& b) {
  if (a.nmt_state != b.nmt_state || a.error_register != b.error_register ||
      a.controller_state != b.controller_state || a.tec != b.tec || a.rec != b.rec ||
      a.heartbeat_producer_ms != b.heartbeat_producer_ms ||
      a.heartbeat_consumer_count != b.heartbeat_consumer_count) {
    return true;
  }
  const std::size_t n = std::min<std::size_t>(a.heartbeat_consumer_count, kMaxHeartbeatConsumers);
  return !std::equal(a.heartbeat_consumers.begin(),
                     a.heartbeat_consumers.begin() + static_cast<std::ptrdiff_t>(n),
                     b.heartbeat_consumers.begin());
}

namespace {

struct IoValues {
  std::array<double, kMaxIoChannels> inputs{};
  std::array<double, kMaxIoChannels> outputs{};
  friend bool operator==(const IoValues&, const IoValues&) = default;
};

void CheckBusName(const std::string& bus) {
  if (bus.empty() || bus.size() > kMaxBusName) {
    throw std::invalid_argument("bus name '" + bus + "' must have 1.." + std::to_string(kMaxBusName) +
                                " characters");
  }
}

}  // namespace

struct NodeTelemetry::Impl {
  Impl(const Participant& participant, NodeTelemetryOptions opts)
      : options(std::move(opts)),
        status_topic(participant),
        io_topic(participant),
        emcy_topic(participant),
        status_writer(participant, status_topic),
        io_writer(participant, io_topic),
        emcy_writer(participant, emcy_topic) {
    emcy_queue.resize(std::max<std::size_t>(options.emcy_queue, 1));
    emcy_batch.reserve(emcy_queue.size());

    CopyBounded(status.bus, options.bus);
    status.node_id = options.node_id;
    CopyBounded(status.device, options.device);
    CopyBoundedAtWord(status.name, options.name);
    status.heartbeat_consumers._buffer = consumers.data();
    status.heartbeat_consumers._maximum = static_cast<std::uint32_t>(consumers.size());
    status.heartbeat_consumers._release = false;  // our buffer, not Cyclone's
    status.publish_period_ms = static_cast<std::uint32_t>(options.period.count());

    CopyBounded(io.bus, options.bus);
    io.node_id = options.node_id;
    for (std::size_t i = 0; i < options.inputs.size(); ++i) {
      CopyBounded(io_inputs[i].name, options.inputs[i].name);
      CopyBounded(io_inputs[i].unit, options.inputs[i].unit);
    }
    for (std::size_t i = 0; i < options.outputs.size(); ++i) {
      CopyBounded(io_outputs[i].name, options.outputs[i].name);
      CopyBounded(io_outputs[i].unit, options.outputs[i].unit);
    }
    io.inputs = {static_cast<std::uint32_t>(io_inputs.size()),
                 static_cast<std::uint32_t>(options.inputs.size()), io_inputs.data(), false};
    io.outputs = {static_cast<std::uint32_t>(io_outputs.size()),
                  static_cast<std::uint32_t>(options.outputs.size()), io_outputs.data(), false};

    CopyBounded(emcy.bus, options.bus);
    emcy.node_id = options.node_id;
  }

  bool has_io() const { return !options.inputs.empty() || !options.outputs.empty(); }

  const NodeTelemetryOptions options;
  TimePoint started{};  ///< the uptime clock's time when the publisher was made

  // DDS entities; the participant deletes the topics.
  Topic<canfleet_telemetry_NodeStatus> status_topic;
  Topic<canfleet_telemetry_IoSnapshot> io_topic;
  Topic<canfleet_telemetry_Emcy> emcy_topic;
  Writer<canfleet_telemetry_NodeStatus> status_writer;
  Writer<canfleet_telemetry_IoSnapshot> io_writer;
  Writer<canfleet_telemetry_Emcy> emcy_writer;

  // Pending slots, guarded by PublisherLoop::mutex().
  NodeStatusSnapshot pending_status;
  bool status_dirty = false;
  IoValues pending_io;
  bool io_dirty = false;
  std::vector<EmcyInfo> emcy_queue;  // ring
  std::size_t emcy_head = 0;
  std::size_t emcy_count = 0;

  // Publisher-thread state.
  NodeStatusSnapshot current_status;
  NodeStatusSnapshot published_status;
  bool status_change = true;  // the first publication goes out at once
  TimePoint status_written{};
  TimePoint status_due{};
  IoValues current_io;
  IoValues published_io;
  bool io_change = true;
  TimePoint io_written{};
  TimePoint io_due{};
  std::vector<EmcyInfo> emcy_batch;
  std::optional<EmcyInfo> last_emcy;

  // Samples in C form, with sequence buffers we own (written without allocating).
  canfleet_telemetry_NodeStatus status{};
  std::array<canfleet_telemetry_HeartbeatConsumer, kMaxHeartbeatConsumers> consumers{};
  canfleet_telemetry_IoSnapshot io{};
  std::array<canfleet_telemetry_IoValue, kMaxIoChannels> io_inputs{};
  std::array<canfleet_telemetry_IoValue, kMaxIoChannels> io_outputs{};
  canfleet_telemetry_Emcy emcy{};

  std::atomic<std::uint64_t> state_writes{0};
  std::atomic<std::uint64_t> event_writes{0};
  std::atomic<std::uint64_t> write_errors{0};
  std::atomic<std::uint64_t> events_dropped{0};

  void Count(dds_return_t rc, std::atomic<std::uint64_t>& ok) {
    (rc == DDS_RETCODE_OK ? ok : write_errors).fetch_add(1, std::memory_order_relaxed);
  }

  void WriteEmcy(const EmcyInfo& e) {
    emcy.code = e.code;
    emcy.error_register = e.error_register;
    std::copy(e.manufacturer.begin(), e.manufacturer.end(), emcy.manufacturer);
    emcy.bus_time_ns = static_cast<std::uint64_t>(e.bus_time.count());
    ++emcy.serial;
    Count(emcy_writer.Write(emcy), event_writes);
  }

  void WriteStatus(TimePoint now) {
    const NodeStatusSnapshot& s = current_status;
    status.nmt_state = ToDds(std::optional<NmtState>(s.nmt_state));
    status.error_register = s.error_register;
    status.controller_state = ToDds(s.controller_state);
    status.tec = s.tec;
    status.rec = s.rec;
    status.heartbeat_producer_ms = s.heartbeat_producer_ms;
    const std::size_t n = std::min<std::size_t>(s.heartbeat_consumer_count, kMaxHeartbeatConsumers);
    for (std::size_t i = 0; i < n; ++i) {
      const HeartbeatConsumerInfo& c = s.heartbeat_consumers[i];
      consumers[i] = {c.node_id, c.time_ms, ToDds(c.state), ToDds(c.last_state)};
    }
    status.heartbeat_consumers._length = static_cast<std::uint32_t>(n);
    status.rpdo_count = s.rpdo_count;
    status.tpdo_count = s.tpdo_count;
    status.uptime_ms = static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::milliseconds>(
            (options.uptime_clock != nullptr ? options.uptime_clock->Now() : now) - started)
            .count());
    status.last_emcy.valid = last_emcy.has_value();
    if (last_emcy) {
      status.last_emcy.code = last_emcy->code;
      status.last_emcy.error_register = last_emcy->error_register;
      status.last_emcy.bus_time_ns = static_cast<std::uint64_t>(last_emcy->bus_time.count());
    }
    ++status.serial;
    Count(status_writer.Write(status), state_writes);
  }

  /// A bool's or an enum's word for `value` (the index of the word); "" for a number or an index
  /// that names no word.
  static void SetIoValue(canfleet_telemetry_IoValue& out, const IoChannel& channel, double value) {
    out.value = value;
    if (channel.words.empty()) return;  // a number: text stays ""
    const double index = std::round(value);
    if (index >= 0 && index < static_cast<double>(channel.words.size()))
      CopyBounded(out.text, channel.words[static_cast<std::size_t>(index)]);
    else
      out.text[0] = '\0';
  }

  void WriteIo() {
    for (std::size_t i = 0; i < options.inputs.size(); ++i)
      SetIoValue(io_inputs[i], options.inputs[i], current_io.inputs[i]);
    for (std::size_t i = 0; i < options.outputs.size(); ++i)
      SetIoValue(io_outputs[i], options.outputs[i], current_io.outputs[i]);
    ++io.serial;
    Count(io_writer.Write(io), state_writes);
  }
};

NodeTelemetry::NodeTelemetry(const Participant& participant, NodeTelemetryOptions options)
    : PublisherLoop(options.min_interval) {
  Init(participant, std::move(options));
}

NodeTelemetry::NodeTelemetry(const Participant& participant, NodeTelemetryOptions options,
                             Scheduler& scheduler)
    : PublisherLoop(options.min_interval, scheduler) {
  Init(participant, std::move(options));
}

void NodeTelemetry::Init(const Participant& participant, NodeTelemetryOptions options) {
  CheckBusName(options.bus);
  if (options.inputs.size() > kMaxIoChannels || options.outputs.size() > kMaxIoChannels) {
    throw std::invalid_argument("at most " + std::to_string(kMaxIoChannels) + " inputs and outputs");
  }
  if (options.period <= std::chrono::milliseconds::zero()) throw std::invalid_argument("period must be > 0");
  impl_ = std::make_unique<Impl>(participant, std::move(options));
  impl_->started = impl_->options.uptime_clock != nullptr ? impl_->options.uptime_clock->Now() : Now();
  Start();
}

NodeTelemetry::~NodeTelemetry() {
  Stop();
}

void NodeTelemetry::UpdateStatus(const NodeStatusSnapshot& status) {
  bool notify;
  {
    const std::lock_guard lock(mutex());
    impl_->pending_status = status;
    impl_->status_dirty = true;
    notify = MarkInputLocked();
  }
  if (notify) Notify();
}

void NodeTelemetry::UpdateIo(std::span<const double> inputs, std::span<const double> outputs) {
  const std::size_t ni = std::min(inputs.size(), impl_->options.inputs.size());
  const std::size_t no = std::min(outputs.size(), impl_->options.outputs.size());
  bool notify;
  {
    const std::lock_guard lock(mutex());
    std::copy_n(inputs.begin(), ni, impl_->pending_io.inputs.begin());
    std::copy_n(outputs.begin(), no, impl_->pending_io.outputs.begin());
    impl_->io_dirty = true;
    notify = MarkInputLocked();
  }
  if (notify) Notify();
}

void NodeTelemetry::PublishEmcy(const EmcyInfo& emcy) {
  bool notify = false;
  {
    const std::lock_guard lock(mutex());
    Impl& m = *impl_;
    if (m.emcy_count == m.emcy_queue.size()) {
      m.events_dropped.fetch_add(1, std::memory_order_relaxed);
    } else {
      m.emcy_queue[(m.emcy_head + m.emcy_count) % m.emcy_queue.size()] = emcy;
      ++m.emcy_count;
      notify = MarkEventLocked();
    }
  }
  if (notify) Notify();
}

PublisherStats NodeTelemetry::stats() const {
  return {impl_->state_writes.load(), impl_->event_writes.load(), impl_->write_errors.load(),
          impl_->events_dropped.load()};
}

void NodeTelemetry::ConsumeLocked(bool inputs) {
  Impl& m = *impl_;
  for (; m.emcy_count > 0; --m.emcy_count) {
    m.emcy_batch.push_back(m.emcy_queue[m.emcy_head]);
    m.emcy_head = (m.emcy_head + 1) % m.emcy_queue.size();
  }
  if (!inputs) return;
  if (m.status_dirty) {
    m.current_status = m.pending_status;
    m.status_dirty = false;
  }
  if (m.io_dirty) {
    m.current_io = m.pending_io;
    m.io_dirty = false;
  }
}

TimePoint NodeTelemetry::Publish(TimePoint now, bool force) {
  Impl& m = *impl_;
  for (const EmcyInfo& e : m.emcy_batch) {
    m.WriteEmcy(e);
    m.last_emcy = e;
    m.status_change = true;
  }
  m.emcy_batch.clear();

  m.status_change = m.status_change || StatusChanged(m.current_status, m.published_status);
  // A flush (or the final write at stop) also takes counter-only changes, which otherwise wait for the
  // period.
  if (force && (m.current_status.rpdo_count != m.published_status.rpdo_count ||
                m.current_status.tpdo_count != m.published_status.tpdo_count)) {
    m.status_change = true;
  }
  if (now >= m.status_due || (m.status_change && (force || now >= m.status_written + min_interval()))) {
    m.WriteStatus(now);
    m.published_status = m.current_status;
    m.status_change = false;
    m.status_written = now;
    m.status_due = now + m.options.period;
  }
  TimePoint next = m.status_due;
  if (m.status_change) next = std::min(next, m.status_written + min_interval());

  if (m.has_io()) {
    m.io_change = m.io_change || !(m.current_io == m.published_io);
    if (now >= m.io_due || (m.io_change && (force || now >= m.io_written + min_interval()))) {
      m.WriteIo();
      m.published_io = m.current_io;
      m.io_change = false;
      m.io_written = now;
      m.io_due = now + m.options.period;
    }
    next = std::min(next, m.io_due);
    if (m.io_change) next = std::min(next, m.io_written + min_interval());
  }
  return next;
}

}  // namespace canfleet::telemetry
