#include "node/canopen/stack/standard_objects.hpp"

#include "node/canopen/emcy/emcy.hpp"
#include "node/canopen/guarding/node_guarding.hpp"
#include "node/canopen/heartbeat/heartbeat_consumer.hpp"
#include "node/canopen/pdo/pdo_service.hpp"
#include "node/canopen/sdo/sdo_server.hpp"
#include "node/canopen/storage/parameter_store.hpp"
#include "node/canopen/sync/sync_service.hpp"

namespace canfleet::canopen {

void AddIdentityObjects(ObjectDictionary& od, const StandardObjectsOptions& o) {
  od.AddVar(0x1000, "Device type", DataType::kUnsigned32, Access::kRo, EncodeLe(o.device_type));
  od.AddVar(0x1008, "Manufacturer device name", DataType::kVisibleString, Access::kConst,
            ToBytes(o.device_name));
  od.AddVar(0x1009, "Manufacturer hardware version", DataType::kVisibleString, Access::kConst,
            ToBytes(o.hardware_version));
  od.AddVar(0x100A, "Manufacturer software version", DataType::kVisibleString, Access::kConst,
            ToBytes(o.software_version));
  Object identity;
  identity.index = 0x1018;
  identity.name = "Identity object";
  identity.code = ObjectCode::kRecord;
  identity.subs.emplace(
      0, MakeSubObject("Highest sub-index supported", DataType::kUnsigned8, Access::kConst, {4}));
  identity.subs.emplace(
      1, MakeSubObject("Vendor-ID", DataType::kUnsigned32, Access::kRo, EncodeLe(o.identity.vendor_id)));
  identity.subs.emplace(2, MakeSubObject("Product code", DataType::kUnsigned32, Access::kRo,
                                         EncodeLe(o.identity.product_code)));
  identity.subs.emplace(
      3, MakeSubObject("Revision number", DataType::kUnsigned32, Access::kRo, EncodeLe(o.identity.revision)));
  identity.subs.emplace(
      4, MakeSubObject("Serial number", DataType::kUnsigned32, Access::kRo, EncodeLe(o.identity.serial)));
  od.Add(std::move(identity));
}

void AddErrorBehaviourObject(ObjectDictionary& od, std::uint8_t entries) {
  Object behaviour;
  behaviour.index = 0x1029;
  behaviour.name = "Error behaviour";
  behaviour.code = ObjectCode::kArray;
  behaviour.subs.emplace(
      0, MakeSubObject("Highest sub-index supported", DataType::kUnsigned8, Access::kConst, {entries}));
  for (std::uint8_t i = 1; i <= entries; ++i) {
    // CiA 301 §7.5.2.32: 0 = pre-operational on error (the default), 1 = no change, 2 = stopped.
    auto sub = MakeSubObject(i == 1 ? "Communication error" : "Error class " + std::to_string(i),
                             DataType::kUnsigned8, Access::kRw, {0});
    sub.high_limit = Bytes{2};
    behaviour.subs.emplace(i, std::move(sub));
  }
  od.Add(std::move(behaviour));
}

void AddStandardObjects(ObjectDictionary& od, const StandardObjectsOptions& o) {
  AddIdentityObjects(od, o);
  AddEmcyObjects(od, o.error_history);
  AddSdoServerObjects(od);
  AddHeartbeatObjects(od, o.heartbeat_consumers);
  AddGuardingObjects(od);
  AddSyncObjects(od, false);
  AddPdoObjects(od, o.rpdos, o.tpdos);
  AddStorageObjects(od);
  AddErrorBehaviourObject(od, o.error_behaviour_subs);
}

}  // namespace canfleet::canopen
