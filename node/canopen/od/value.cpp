#include "node/canopen/od/value.hpp"

#include <cstdio>

namespace canfleet::canopen {

double DecodeAsDouble(DataType type, std::span<const std::uint8_t> bytes) {
  if (type == DataType::kReal32 && bytes.size() >= 4) {
    return std::bit_cast<float>(static_cast<std::uint32_t>(DecodeUnsignedLe(bytes.first(4))));
  }
  if (type == DataType::kReal64 && bytes.size() >= 8) {
    return std::bit_cast<double>(DecodeUnsignedLe(bytes.first(8)));
  }
  if (IsSigned(type)) return static_cast<double>(DecodeSignedLe(bytes));
  return static_cast<double>(DecodeUnsignedLe(bytes));
}

int CompareNumeric(DataType type, std::span<const std::uint8_t> a, std::span<const std::uint8_t> b) {
  if (IsReal(type)) {
    double x = DecodeAsDouble(type, a), y = DecodeAsDouble(type, b);
    return x < y ? -1 : (x > y ? 1 : 0);
  }
  if (IsSigned(type)) {
    auto x = DecodeSignedLe(a), y = DecodeSignedLe(b);
    return x < y ? -1 : (x > y ? 1 : 0);
  }
  auto x = DecodeUnsignedLe(a), y = DecodeUnsignedLe(b);
  return x < y ? -1 : (x > y ? 1 : 0);
}

std::string FormatValue(DataType type, std::span<const std::uint8_t> bytes) {
  char buf[64];
  if (type == DataType::kVisibleString) {
    // Appended piecewise: GCC 12 at -O3 reports a false -Wrestrict inside string operator+ (PR 105651).
    std::string out;
    out.reserve(bytes.size() + 2);
    out.push_back('"');
    out.append(bytes.begin(), bytes.end());
    out.push_back('"');
    return out;
  }
  if (IsVariableLength(type)) {
    std::string out;
    for (auto b : bytes) {
      std::snprintf(buf, sizeof buf, "%02X", b);
      out += buf;
    }
    return out;
  }
  if (IsReal(type)) {
    std::snprintf(buf, sizeof buf, "%g", DecodeAsDouble(type, bytes));
  } else if (IsSigned(type)) {
    std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(DecodeSignedLe(bytes)));
  } else {
    std::snprintf(buf, sizeof buf, "%llu", static_cast<unsigned long long>(DecodeUnsignedLe(bytes)));
  }
  return buf;
}

}  // namespace canfleet::canopen
