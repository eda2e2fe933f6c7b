#include "node/canopen/heartbeat/heartbeat_objects.hpp"

#include <string>
#include <utility>

namespace canfleet::canopen {

void AddHeartbeatObjects(ObjectDictionary& od, std::uint8_t consumer_entries) {
  od.AddVar(kProducerHeartbeatTimeIndex, "Producer heartbeat time", DataType::kUnsigned16, Access::kRw,
            EncodeLe<std::uint16_t>(0));
  if (consumer_entries == 0) return;
  if (consumer_entries > 127) consumer_entries = 127;
  Object obj;
  obj.index = kConsumerHeartbeatTimeIndex;
  obj.name = "Consumer heartbeat time";
  obj.code = ObjectCode::kArray;
  SubObject count;
  count.name = "Highest sub-index supported";
  count.type = DataType::kUnsigned8;
  count.access = Access::kRo;
  count.default_value = {consumer_entries};
  obj.subs.emplace(0, std::move(count));
  for (std::uint8_t i = 1; i <= consumer_entries; ++i) {
    SubObject entry;
    entry.name = "Consumer heartbeat time " + std::to_string(i);
    entry.type = DataType::kUnsigned32;
    entry.access = Access::kRw;
    entry.default_value = EncodeLe<std::uint32_t>(0);
    obj.subs.emplace(i, std::move(entry));
  }
  od.Add(std::move(obj));
}

}  // namespace canfleet::canopen
