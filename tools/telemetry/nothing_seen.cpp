#include "tools/telemetry/nothing_seen.hpp"

namespace canfleet::tools {

std::string NothingSeenHint(const char* tool, const telemetry::DdsOptions& dds) {
  return std::string(tool) + ": no fleet seen on DDS domain " + std::to_string(dds.domain_id) + " with " +
         telemetry::DescribeConfig(dds) +
         ". A fleet started with another --dds-domain, --dds-config or CYCLONEDDS_URI is seen only with the "
         "same "
         "options here; a fleet in containers: scripts/docker-fleet.sh top.";
}

}  // namespace canfleet::tools
