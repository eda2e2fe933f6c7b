#include "telemetry/topics.hpp"

namespace canfleet::telemetry {

namespace {

// A writer blocks at most this long when Cyclone's unacknowledged-data limit is reached (a reader
// that stopped acknowledging). Writes happen on the publisher's own thread, never on the CAN path;
// after this the write fails with a timeout, is counted, and the next period tries again.
constexpr dds_duration_t kMaxBlocking = DDS_MSECS(100);

QosPtr Profile(std::int32_t depth) {
  QosPtr qos = MakeQos();
  dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, kMaxBlocking);
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, depth);
  dds_qset_durability(qos.get(), DDS_DURABILITY_TRANSIENT_LOCAL);
  // Cyclone sizes the transient-local history it keeps for late joiners from durability_service,
  // not from history (default depth 1): without this a late reader would get one event, not `depth`.
  dds_qset_durability_service(qos.get(), 0, DDS_HISTORY_KEEP_LAST, depth, DDS_LENGTH_UNLIMITED,
                              DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  return qos;
}

}  // namespace

QosPtr StateQos() {
  return Profile(1);
}
QosPtr EventQos() {
  return Profile(kEventHistoryDepth);
}
QosPtr StateReaderQos() {
  return Profile(1);
}
QosPtr EventReaderQos() {
  return Profile(kEventHistoryDepth);
}

}  // namespace canfleet::telemetry
