#include "node/devices/embedded_eds.hpp"

#include <zlib.h>

#include <stdexcept>

namespace canfleet::devices {

std::string EmbeddedEds::Text() const {
  std::string text(size, '\0');
  uLongf inflated = static_cast<uLongf>(size);
  const int rc = uncompress(reinterpret_cast<Bytef*>(text.data()), &inflated, deflated.data(),
                            static_cast<uLong>(deflated.size()));
  if (rc != Z_OK || inflated != size) {
    throw std::runtime_error("embedded EDS does not inflate (zlib " + std::to_string(rc) + ", " +
                             std::to_string(inflated) + " of " + std::to_string(size) + " bytes)");
  }
  return text;
}

}  // namespace canfleet::devices
