#include "node/canopen/emcy/emcy.hpp"

namespace canfleet::canopen {

void AddEmcyObjects(ObjectDictionary& od, std::uint8_t history_entries) {
  od.AddVar(0x1001, "Error register", DataType::kUnsigned8, Access::kRo, {0}, /*pdo_mappable=*/true);

  if (history_entries > 0) {
    Object field;
    field.index = 0x1003;
    field.name = "Pre-defined error field";
    field.code = ObjectCode::kArray;
    SubObject count;
    count.name = "Number of errors";
    count.type = DataType::kUnsigned8;
    count.access = Access::kRw;
    count.default_value = {0};
    field.subs.emplace(0, std::move(count));
    // Sub-index FFh of an ARRAY is reserved: at most 254 entries.
    const unsigned entries = history_entries > 0xFE ? 0xFE : history_entries;
    for (unsigned sub = 1; sub <= entries; ++sub) {
      SubObject entry;
      entry.name = "Standard error field";
      entry.type = DataType::kUnsigned32;
      entry.access = Access::kRo;
      entry.default_value = EncodeLe<std::uint32_t>(0);
      field.subs.emplace(static_cast<std::uint8_t>(sub), std::move(entry));
    }
    od.Add(std::move(field));
  }

  SubObject& cob_id =
      od.AddVar(0x1014, "COB-ID EMCY", DataType::kUnsigned32, Access::kRw, EncodeLe<std::uint32_t>(0x80));
  cob_id.default_adds_node_id = true;  // $NODEID+0x80
  od.AddVar(0x1015, "Inhibit time EMCY", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(0));
}

}  // namespace canfleet::canopen
