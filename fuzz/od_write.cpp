// Fuzzes object dictionary writes with arbitrary index, sub-index and payload: any input must
// give an abort code or success, never a crash.
#include <cstddef>
#include <cstdint>

#include "node/canopen/od/object_dictionary.hpp"

using namespace canfleet::canopen;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static ObjectDictionary* od = [] {
    auto* d = new ObjectDictionary;
    d->AddVar(0x1017, "hb", DataType::kUnsigned16, Access::kRw, EncodeLe<std::uint16_t>(0));
    auto& lim = d->AddVar(0x2000, "lim", DataType::kInteger32, Access::kRw, EncodeLe<std::int32_t>(0));
    lim.low_limit = EncodeLe<std::int32_t>(-5);
    lim.high_limit = EncodeLe<std::int32_t>(5);
    d->AddVar(0x2001, "b", DataType::kBoolean, Access::kRw, {0});
    d->AddVar(0x2002, "s", DataType::kVisibleString, Access::kRw, {});
    d->AddVar(0x2003, "r", DataType::kReal64, Access::kRo, EncodeLe<double>(1.0));
    return d;
  }();
  if (size < 4) return 0;
  std::uint16_t index =
      static_cast<std::uint16_t>(0x1017 + (data[0] % 8) * (data[1] & 1 ? 1 : 0x1000 - 0x17 + 0x1000));
  std::uint8_t sub = data[2] % 3;
  Origin origin = static_cast<Origin>(data[3] % 3);
  std::span<const std::uint8_t> payload(data + 4, size - 4);
  (void)od->Write(index, sub, payload, origin);
  Bytes out;
  (void)od->Read(index, sub, out, origin);
  return 0;
}
