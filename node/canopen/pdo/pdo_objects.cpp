#include "node/canopen/pdo/pdo_objects.hpp"

#include <algorithm>
#include <array>
#include <string>

namespace canfleet::canopen {

namespace {

// Pre-defined connection set (CiA 301, facts §1): function codes of PDOs 1–4.
constexpr std::array<std::uint32_t, 4> kRpdoFunctionCodes{0x200, 0x300, 0x400, 0x500};
constexpr std::array<std::uint32_t, 4> kTpdoFunctionCodes{0x180, 0x280, 0x380, 0x480};

void AddPdo(ObjectDictionary& od, bool transmit, std::size_t number) {
  const std::string kind = transmit ? "TPDO" : "RPDO";
  const auto offset = static_cast<std::uint16_t>(number - 1);

  Object comm;
  comm.index = static_cast<std::uint16_t>((transmit ? kTpdoCommBase : kRpdoCommBase) + offset);
  comm.name = kind + " communication parameter " + std::to_string(number);
  comm.code = ObjectCode::kRecord;
  const std::uint8_t highest = transmit ? 6 : 5;
  comm.subs.emplace(
      0, MakeSubObject("Highest sub-index supported", DataType::kUnsigned8, Access::kConst, {highest}));
  SubObject cob_id = MakeSubObject("COB-ID used by " + kind, DataType::kUnsigned32, Access::kRw, {});
  if (number <= 4) {
    const auto& codes = transmit ? kTpdoFunctionCodes : kRpdoFunctionCodes;
    cob_id.default_value = EncodeLe<std::uint32_t>(kPdoCobIdNoRtr | codes[number - 1]);
    cob_id.default_adds_node_id = true;
  } else {
    cob_id.default_value = EncodeLe<std::uint32_t>(kPdoCobIdInvalid);
  }
  cob_id.value = cob_id.default_value;
  comm.subs.emplace(1, std::move(cob_id));
  comm.subs.emplace(
      2, MakeSubObject("Transmission type", DataType::kUnsigned8, Access::kRw, {kTransmissionEventProfile}));
  comm.subs.emplace(
      3, MakeSubObject("Inhibit time", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(0)));
  comm.subs.emplace(4, MakeSubObject("Compatibility entry", DataType::kUnsigned8, Access::kRw, {0}));
  comm.subs.emplace(
      5, MakeSubObject("Event timer", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(0)));
  if (transmit)
    comm.subs.emplace(6, MakeSubObject("SYNC start value", DataType::kUnsigned8, Access::kRw, {0}));
  od.Add(std::move(comm));

  Object mapping;
  mapping.index = static_cast<std::uint16_t>((transmit ? kTpdoMappingBase : kRpdoMappingBase) + offset);
  mapping.name = kind + " mapping parameter " + std::to_string(number);
  mapping.code = ObjectCode::kRecord;
  mapping.subs.emplace(0, MakeSubObject("Number of mapped application objects in PDO", DataType::kUnsigned8,
                                        Access::kRw, {0}));
  for (std::uint8_t i = 1; i <= kDefaultMappingEntries; ++i) {
    mapping.subs.emplace(i, MakeSubObject("Application object " + std::to_string(i), DataType::kUnsigned32,
                                          Access::kRw, EncodeLe<std::uint32_t>(0)));
  }
  od.Add(std::move(mapping));
}

}  // namespace

void AddPdoObjects(ObjectDictionary& od, std::size_t rpdos, std::size_t tpdos) {
  for (std::size_t n = 1; n <= std::min(rpdos, kMaxPdos); ++n)
    AddPdo(od, false, n);
  for (std::size_t n = 1; n <= std::min(tpdos, kMaxPdos); ++n)
    AddPdo(od, true, n);
}

}  // namespace canfleet::canopen
