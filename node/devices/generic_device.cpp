#include "node/devices/generic_device.hpp"

#include "node/devices/eds_dictionary.hpp"

namespace canfleet::devices {

void GenericDevice::Build(std::size_t port, canopen::ObjectDictionary& od) {
  (void)port;
  od = DictionaryFromEdsFile(eds_);
}

}  // namespace canfleet::devices
