#pragma once
/// @file The CiA 301 communication profile area of a generic slave, for nodes started without an
/// EDS-defined device and for tests: 1000h, 1001h/1003h, 1005h–1007h, 1008h–100Ah, 100Ch/100Dh,
/// 1010h/1011h, 1014h/1015h, 1016h/1017h, 1018h, 1019h, 1029h, 1200h, PDO parameters.

#include <cstdint>
#include <string>

#include "node/canopen/lss/lss_slave.hpp"
#include "node/canopen/od/object_dictionary.hpp"

namespace canfleet::canopen {

struct StandardObjectsOptions {
  std::uint32_t device_type = 0;  ///< 1000h
  LssAddress identity{};          ///< 1018h sub1..4
  std::string device_name = "canfleet generic node";
  std::string hardware_version = "1";
  std::string software_version = "1";
  std::uint8_t error_history = 8;        ///< 1003h entries
  std::uint8_t heartbeat_consumers = 4;  ///< 1016h entries
  std::uint8_t rpdos = 4, tpdos = 4;
  std::uint8_t error_behaviour_subs = 1;  ///< 1029h entries (1 = communication error)
};

void AddIdentityObjects(ObjectDictionary& od, const StandardObjectsOptions& options);
void AddErrorBehaviourObject(ObjectDictionary& od, std::uint8_t entries);
/// Everything above: the full communication area of a generic DS-301 slave.
void AddStandardObjects(ObjectDictionary& od, const StandardObjectsOptions& options);

}  // namespace canfleet::canopen
