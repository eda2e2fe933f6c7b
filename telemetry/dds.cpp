#include "telemetry/dds.hpp"

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

/// An explicitly created domain (dds_create_domain), shared by the participants of this process.
/// Deleting a domain deletes every participant in it, so it must outlive all of them: the
/// participants hold it by shared_ptr and the registry only by weak_ptr.
class DomainRef {
 public:
  DomainRef(std::uint32_t id, const std::string& config_file)
      : config_file_(config_file),
        entity_(CheckDds(dds_create_domain(id, ("file://" + config_file).c_str()),
                         "create domain " + std::to_string(id) + " from " + config_file)) {}
  const std::string& config_file() const { return config_file_; }

 private:
  std::string config_file_;
  Entity entity_;
};

namespace {

std::shared_ptr<DomainRef> AcquireDomain(const DdsOptions& options) {
  static std::mutex mutex;
  static std::map<std::uint32_t, std::weak_ptr<DomainRef>> domains;
  const std::lock_guard lock(mutex);
  if (auto existing = domains[options.domain_id].lock()) {
    if (existing->config_file() != options.config_file) {
      throw DdsError("domain " + std::to_string(options.domain_id) + " already configured from " +
                         existing->config_file() + ", not " + options.config_file,
                     DDS_RETCODE_PRECONDITION_NOT_MET);
    }
    return existing;
  }
  auto created = std::make_shared<DomainRef>(options.domain_id, options.config_file);
  domains[options.domain_id] = created;
  return created;
}

}  // namespace

Participant::Participant(const DdsOptions& options) {
  if (!options.config_file.empty()) domain_ = AcquireDomain(options);
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
