#include "telemetry/dds.hpp"

#include <cstdlib>
#include <map>
#include <mutex>

namespace canfleet::telemetry {

DdsError::DdsError(std::string_view what, dds_return_t code)
    : std::runtime_error(std::string(what) + ": " + dds_strretcode(code < 0 ? -code : code)), code_(code) {}

dds_entity_t CheckDds(dds_entity_t result, std::string_view what) {
  if (result < 0) throw DdsError(what, result);
  return result;
}

QosPtr MakeQos() {
  QosPtr qos(dds_create_qos());
  if (!qos) throw DdsError("create qos", DDS_RETCODE_OUT_OF_RESOURCES);
  return qos;
}

void Entity::Reset() {
  if (handle_ > 0) dds_delete(handle_);
  handle_ = 0;
}

namespace {

/// DdsDiscovery::kMonitorsOnly, appended to the user's configuration (later settings win; Peers
/// are added to the configuration's own):
/// - AllowMulticast false: join no multicast group, so other announcers' SPDP never reaches us;
///   our own SPDP still goes to the peers, and 239.255.0.1 (Cyclone's default SPDP group, which
///   monitors with a multicast configuration join) is one of them;
/// - ParticipantIndex none: no fixed port (nobody probes for us; we are found by announcing);
/// - MaxAutoParticipantIndex 19: the configuration's unicast peers (127.0.0.1 in the loopback
///   configuration) are probed at participant indexes 0..19, where the monitors are;
/// - SPDPInterval 1 s: a monitor started after us finds us within a second (Cyclone's default
///   repeats the announcement only every 8 s or so);
/// - Sizing: receive buffers of 32 KiB in chunks of 16 KiB (Cyclone: 1 MiB and 128 KiB), and one
///   receive thread. A writer receives only discovery and acknowledgements, in packets below
///   Cyclone's MaxMessageSize (14720 B; a larger one would be dropped and sent again in smaller
///   pieces). Packets are laid one after another in a receive buffer, so with 1 MiB buffers a node
///   touched a page more every half minute for hours (RSS +8 kB a minute for as long as it ran,
///   measured, towards +1 MiB per receive thread); 32 KiB buffers bound that to a few pages.
constexpr const char* kMonitorsOnlyConfig =
    "<CycloneDDS xmlns=\"https://cdds.io/config\"><Domain Id=\"any\">"
    "<General><AllowMulticast>false</AllowMulticast></General>"
    "<Discovery><ParticipantIndex>none</ParticipantIndex>"
    "<MaxAutoParticipantIndex>19</MaxAutoParticipantIndex>"
    "<SPDPInterval>1s</SPDPInterval>"
    "<Peers><Peer address=\"239.255.0.1\"/></Peers></Discovery>"
    "<Internal><MultipleReceiveThreads>false</MultipleReceiveThreads></Internal>"
    "<Sizing><ReceiveBufferSize>32KiB</ReceiveBufferSize>"
    "<ReceiveBufferChunkSize>16KiB</ReceiveBufferChunkSize></Sizing>"
    "</Domain></CycloneDDS>";

}  // namespace

namespace {

const char* CycloneddsUri() {
  const char* uri = std::getenv("CYCLONEDDS_URI");
  return uri != nullptr && *uri != '\0' ? uri : nullptr;
}

}  // namespace

std::string DescribeConfig(const DdsOptions& options) {
  if (!options.config_file.empty()) return options.config_file;
  if (const char* uri = CycloneddsUri()) return std::string("CYCLONEDDS_URI=") + uri;
  return "the built-in loopback configuration (this host only)";
}

std::string CycloneConfig(const DdsOptions& options) {
  // The domain is always created explicitly, which ignores CYCLONEDDS_URI: carry it over.
  std::string config;
  if (!options.config_file.empty()) {
    config = "file://" + options.config_file;
  } else if (const char* uri = CycloneddsUri()) {
    config = uri;
  } else {
    config = kLoopbackConfigXml;
  }
  if (options.discovery == DdsDiscovery::kMonitorsOnly) {
    config += ',';
    config += kMonitorsOnlyConfig;
  }
  return config;
}

/// An explicitly created domain (dds_create_domain), shared by the participants of this process.
/// Deleting a domain deletes every participant in it, so it must outlive all of them: the
/// participants hold it by shared_ptr and the registry only by weak_ptr.
class DomainRef {
 public:
  DomainRef(std::uint32_t id, const std::string& config, const std::string& description)
      : config_(config),
        entity_(CheckDds(dds_create_domain(id, config.c_str()),
                         "create domain " + std::to_string(id) + " from " + description)) {}
  const std::string& config() const { return config_; }

 private:
  std::string config_;
  Entity entity_;
};

namespace {

std::shared_ptr<DomainRef> AcquireDomain(const DdsOptions& options, const std::string& config) {
  static std::mutex mutex;
  static std::map<std::uint32_t, std::weak_ptr<DomainRef>> domains;
  const std::lock_guard lock(mutex);
  const std::string description = DescribeConfig(options);
  if (auto existing = domains[options.domain_id].lock()) {
    if (existing->config() != config) {
      throw DdsError("domain " + std::to_string(options.domain_id) +
                         " already configured otherwise, not from " + description,
                     DDS_RETCODE_PRECONDITION_NOT_MET);
    }
    return existing;
  }
  auto created = std::make_shared<DomainRef>(options.domain_id, config, description);
  domains[options.domain_id] = created;
  return created;
}

}  // namespace

Participant::Participant(const DdsOptions& options) {
  domain_ = AcquireDomain(options, CycloneConfig(options));
  entity_ = Entity(CheckDds(dds_create_participant(options.domain_id, nullptr, nullptr),
                            "create participant on domain " + std::to_string(options.domain_id)));
}

Participant::~Participant() = default;
Participant::Participant(Participant&&) noexcept = default;
Participant& Participant::operator=(Participant&& other) noexcept {
  if (this != &other) {
    entity_ = std::move(other.entity_);  // delete our participant before letting go of its domain
    domain_ = std::move(other.domain_);
  }
  return *this;
}

WaitSet::WaitSet(const Participant& participant)
    : entity_(CheckDds(dds_create_waitset(participant.handle()), "create waitset")) {
  // Attached to itself so that Trigger() wakes Wait() (as in Cyclone's pong.c).
  CheckDds(dds_waitset_attach(entity_.handle(), entity_.handle(), entity_.handle()), "attach waitset");
}

void WaitSet::AttachDataAvailable(dds_entity_t reader) {
  // A read condition on any sample state is level-triggered: it stays set while the reader holds
  // samples, so a wake-up is never lost between a take and the next wait. It belongs to the reader
  // and is deleted with it.
  const dds_entity_t condition =
      CheckDds(dds_create_readcondition(reader, DDS_ANY_STATE), "create readcondition");
  CheckDds(dds_waitset_attach(entity_.handle(), condition, reader), "attach readcondition");
}

bool WaitSet::Wait(std::chrono::nanoseconds timeout) {
  const dds_return_t n = dds_waitset_wait(entity_.handle(), nullptr, 0, timeout.count());
  return n > 0;
}

void WaitSet::Trigger() {
  dds_waitset_set_trigger(entity_.handle(), true);
}

void WaitSet::ClearTrigger() {
  dds_waitset_set_trigger(entity_.handle(), false);
}

}  // namespace canfleet::telemetry
