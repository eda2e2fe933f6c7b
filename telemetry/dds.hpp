#pragma once
/// @file Small RAII types over the Cyclone DDS C API (Debian packages no C++ binding).
///
/// Shaped after cyclonedds-cxx's helloworld: a move-only Participant owns its children (its
/// destructor's dds_delete deletes them recursively); Topic, Writer and Reader are declared after
/// it and so destroyed first. Every failed create throws DdsError at startup, naming what failed
/// and dds_strretcode(); the write/take paths return codes instead, since they run in steady state.

#include <dds/dds.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace canfleet::telemetry {

/// A DDS call failed; `code` is the (negative) dds_return_t.
class DdsError : public std::runtime_error {
 public:
  DdsError(std::string_view what, dds_return_t code);
  dds_return_t code() const { return code_; }

 private:
  dds_return_t code_;
};

/// Returns `result` if it is a valid entity/return code, throws DdsError naming `what` otherwise.
dds_entity_t CheckDds(dds_entity_t result, std::string_view what);

struct QosDeleter {
  void operator()(dds_qos_t* qos) const { dds_delete_qos(qos); }
};
/// A QoS object; dds_create_qos() never fails in 0.10 but is checked anyway.
using QosPtr = std::unique_ptr<dds_qos_t, QosDeleter>;
QosPtr MakeQos();

/// Owns one entity handle: dds_delete() on destruction. Move-only.
class Entity {
 public:
  Entity() = default;
  explicit Entity(dds_entity_t handle) : handle_(handle) {}
  ~Entity() { Reset(); }
  Entity(Entity&& other) noexcept : handle_(std::exchange(other.handle_, 0)) {}
  Entity& operator=(Entity&& other) noexcept {
    if (this != &other) {
      Reset();
      handle_ = std::exchange(other.handle_, 0);
    }
    return *this;
  }
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;

  dds_entity_t handle() const { return handle_; }
  void Reset();

 private:
  dds_entity_t handle_ = 0;
};

/// Whom a participant discovers. Cyclone's default, every participant discovers every other one,
/// costs each process state and discovery traffic per peer (about 30 kB of RSS per peer: a node of
/// a 100-node fleet used 12.7 MB, issue 7), although a node only writes and nobody but the
/// monitors reads it. So programs that only write announce themselves to the monitors instead.
enum class DdsDiscovery : std::uint8_t {
  /// Discover every participant of the domain (Cyclone's default): monitors (canfleet top and
  /// watch, tests' readers) and anything that reads.
  kAll,
  /// Only announce: send our participant announcement (SPDP) every second to the monitors (the
  /// default SPDP multicast group 239.255.0.1, and the configuration's peers at participant
  /// indexes 0..19), listen to nobody's announcements, take no participant index. A monitor that
  /// hears us answers, and we discover it; other announcers never meet. For programs that only
  /// write: canfleet-node, canfleet-broker, canfleet up, canfleet-fake-fleet.
  kMonitorsOnly,
};

/// The options every canfleet program takes: which DDS domain, and which Cyclone configuration.
struct DdsOptions {
  std::uint32_t domain_id = 0;
  /// Path of a Cyclone XML configuration (telemetry/cyclonedds-loopback.xml for one host,
  /// telemetry/cyclonedds-default.xml in containers). Empty: the CYCLONEDDS_URI environment
  /// variable, else the loopback configuration compiled in (kLoopbackConfigXml).
  std::string config_file;
  DdsDiscovery discovery = DdsDiscovery::kAll;
};

/// telemetry/cyclonedds-loopback.xml, compiled in: the configuration of every canfleet program that
/// is given none (no --dds-config, no CYCLONEDDS_URI). Every process of a fleet and every monitor on
/// the host then meet over loopback with no setup: a `canfleet top` in a second terminal sees the
/// fleet `canfleet up` started in the first. (Cyclone's own default, multicast on the first
/// interface, met nothing of a fleet started with the loopback file, which the demo used.)
extern const char* const kLoopbackConfigXml;

/// Where the configuration of `options` comes from, for messages: the file, "CYCLONEDDS_URI" or
/// "the built-in loopback configuration".
std::string DescribeConfig(const DdsOptions& options);

/// The Cyclone configuration `options` ask for, as dds_create_domain takes it: the file, else
/// CYCLONEDDS_URI, else the built-in loopback configuration; followed by the announce-only
/// settings for DdsDiscovery::kMonitorsOnly.
std::string CycloneConfig(const DdsOptions& options);

class DomainRef;

/// A domain participant. With a configuration (CycloneConfig), the domain is created explicitly
/// from it (dds_create_domain) and shared by every Participant of this process on that domain id.
class Participant {
 public:
  explicit Participant(const DdsOptions& options = {});
  ~Participant();
  Participant(Participant&&) noexcept;
  Participant& operator=(Participant&&) noexcept;
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  dds_entity_t handle() const { return entity_.handle(); }

 private:
  std::shared_ptr<DomainRef> domain_;  // released after entity_ (declared first)
  Entity entity_;
};

/// What the generic wrappers need to know about an idlc-generated type; specialised in topics.hpp.
template <typename T>
struct TopicTraits;

/// A topic of type T on a participant. Not owning: the participant deletes it (topics in Cyclone
/// are shared per participant and may only be deleted once their readers/writers are gone).
template <typename T>
class Topic {
 public:
  /// @param qos null: the topic's QoS profile from TopicTraits<T>::Qos().
  explicit Topic(const Participant& participant, const dds_qos_t* qos = nullptr) {
    QosPtr profile;
    if (qos == nullptr) {
      profile = TopicTraits<T>::Qos();
      qos = profile.get();
    }
    handle_ = CheckDds(dds_create_topic(participant.handle(), &TopicTraits<T>::Descriptor(),
                                        TopicTraits<T>::kName, qos, nullptr),
                       std::string("create topic ") + TopicTraits<T>::kName);
  }
  dds_entity_t handle() const { return handle_; }

 private:
  dds_entity_t handle_ = 0;
};

/// A data writer of T. Deleting a writer of a keyed topic disposes its instances (the default
/// writer_data_lifecycle), so a cleanly stopped node disappears from every monitor.
template <typename T>
class Writer {
 public:
  /// @param qos null: the topic's profile (TopicTraits<T>::Qos()).
  Writer(const Participant& participant, const Topic<T>& topic, const dds_qos_t* qos = nullptr) {
    QosPtr profile;
    if (qos == nullptr) {
      profile = TopicTraits<T>::Qos();
      qos = profile.get();
    }
    entity_ = Entity(CheckDds(dds_create_writer(participant.handle(), topic.handle(), qos, nullptr),
                              std::string("create writer ") + TopicTraits<T>::kName));
  }

  /// Writes one sample; returns DDS_RETCODE_OK or the error (never throws).
  dds_return_t Write(const T& sample) const { return dds_write(entity_.handle(), &sample); }
  /// Disposes the instance whose key fields are in `key`.
  dds_return_t Dispose(const T& key) const { return dds_dispose(entity_.handle(), &key); }
  /// Number of readers currently matched (for tests and benchmarks waiting on discovery).
  std::size_t MatchedReaders() const {
    dds_publication_matched_status_t status{};
    if (dds_get_publication_matched_status(entity_.handle(), &status) < 0) return 0;
    return status.current_count;
  }
  dds_entity_t handle() const { return entity_.handle(); }

 private:
  Entity entity_;
};

/// A data reader of T that takes or reads into samples it owns and reuses: Cyclone deserialises
/// into the existing sample, reusing its sequence buffers, so steady-state reading does not allocate
/// once the buffers have grown to the largest sample seen.
template <typename T>
class Reader {
 public:
  /// @param batch the most samples one Take()/Read() call returns.
  Reader(const Participant& participant, const Topic<T>& topic, const dds_qos_t* qos = nullptr,
         std::size_t batch = 64)
      : samples_(batch), pointers_(batch), infos_(batch) {
    QosPtr profile;
    if (qos == nullptr) {
      profile = TopicTraits<T>::ReaderQos();
      qos = profile.get();
    }
    entity_ = Entity(CheckDds(dds_create_reader(participant.handle(), topic.handle(), qos, nullptr),
                              std::string("create reader ") + TopicTraits<T>::kName));
    for (std::size_t i = 0; i < batch; ++i)
      pointers_[i] = &samples_[i];
  }
  ~Reader() {
    // The samples' contents (sequence buffers) were allocated by Cyclone's deserialiser.
    for (T& sample : samples_)
      dds_sample_free(&sample, &TopicTraits<T>::Descriptor(), DDS_FREE_CONTENTS);
  }
  Reader(Reader&&) = delete;  // pointers_ point into samples_
  Reader& operator=(Reader&&) = delete;

  /// Takes up to `batch` samples and calls `fn(const T&, const dds_sample_info_t&)` for each one,
  /// including invalid samples (info.valid_data == false: only the key fields are set; the
  /// instance was disposed or lost its writers). Returns the number of samples or a negative error.
  template <typename Fn>
  dds_return_t Take(Fn&& fn) {
    return Deliver(dds_take(entity_.handle(), pointers_.data(), infos_.data(), samples_.size(),
                            static_cast<std::uint32_t>(samples_.size())),
                   fn);
  }
  /// As Take(), but leaves the samples in the reader cache (marked read).
  template <typename Fn>
  dds_return_t Read(Fn&& fn) {
    return Deliver(dds_read(entity_.handle(), pointers_.data(), infos_.data(), samples_.size(),
                            static_cast<std::uint32_t>(samples_.size())),
                   fn);
  }
  /// Takes until the reader is empty; returns the total or a negative error.
  template <typename Fn>
  dds_return_t TakeAll(Fn&& fn) {
    dds_return_t total = 0;
    for (;;) {
      const dds_return_t n = Take(fn);
      if (n < 0) return n;
      total += n;
      if (static_cast<std::size_t>(n) < samples_.size()) return total;
    }
  }
  dds_entity_t handle() const { return entity_.handle(); }

 private:
  template <typename Fn>
  dds_return_t Deliver(dds_return_t n, Fn& fn) {
    for (dds_return_t i = 0; i < n; ++i)
      fn(samples_[static_cast<std::size_t>(i)], infos_[static_cast<std::size_t>(i)]);
    return n;
  }

  Entity entity_;
  std::vector<T> samples_;  // value-initialised: empty sequences, zeroed strings
  std::vector<void*> pointers_;
  std::vector<dds_sample_info_t> infos_;
};

/// A waitset that wakes on data available at any attached reader, or on Trigger() (which is
/// async-signal-safe in Cyclone: pong.c calls it from a SIGINT handler).
class WaitSet {
 public:
  explicit WaitSet(const Participant& participant);
  /// Wakes Wait() when `reader` has data available.
  void AttachDataAvailable(dds_entity_t reader);
  /// Waits up to `timeout`; true if woken by data or a trigger, false on timeout.
  bool Wait(std::chrono::nanoseconds timeout);
  void Trigger();
  void ClearTrigger();

 private:
  Entity entity_;
};

}  // namespace canfleet::telemetry
