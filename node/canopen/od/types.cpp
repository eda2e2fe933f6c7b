#include "node/canopen/od/types.hpp"

#include <algorithm>
#include <cctype>
#include <string>

namespace canfleet::canopen {

std::optional<std::size_t> FixedSize(DataType type) {
  switch (type) {
    case DataType::kBoolean:
    case DataType::kInteger8:
    case DataType::kUnsigned8:
      return 1;
    case DataType::kInteger16:
    case DataType::kUnsigned16:
      return 2;
    case DataType::kInteger24:
    case DataType::kUnsigned24:
      return 3;
    case DataType::kInteger32:
    case DataType::kUnsigned32:
    case DataType::kReal32:
      return 4;
    case DataType::kInteger40:
    case DataType::kUnsigned40:
      return 5;
    case DataType::kInteger48:
    case DataType::kUnsigned48:
    case DataType::kTimeOfDay:
    case DataType::kTimeDifference:
      return 6;
    case DataType::kInteger56:
    case DataType::kUnsigned56:
      return 7;
    case DataType::kInteger64:
    case DataType::kUnsigned64:
    case DataType::kReal64:
      return 8;
    default:
      return std::nullopt;
  }
}

bool IsVariableLength(DataType type) {
  return type == DataType::kVisibleString || type == DataType::kOctetString ||
         type == DataType::kUnicodeString || type == DataType::kDomain;
}

bool IsSigned(DataType type) {
  switch (type) {
    case DataType::kInteger8:
    case DataType::kInteger16:
    case DataType::kInteger24:
    case DataType::kInteger32:
    case DataType::kInteger40:
    case DataType::kInteger48:
    case DataType::kInteger56:
    case DataType::kInteger64:
      return true;
    default:
      return false;
  }
}

bool IsUnsigned(DataType type) {
  switch (type) {
    case DataType::kBoolean:
    case DataType::kUnsigned8:
    case DataType::kUnsigned16:
    case DataType::kUnsigned24:
    case DataType::kUnsigned32:
    case DataType::kUnsigned40:
    case DataType::kUnsigned48:
    case DataType::kUnsigned56:
    case DataType::kUnsigned64:
      return true;
    default:
      return false;
  }
}

bool IsReal(DataType type) {
  return type == DataType::kReal32 || type == DataType::kReal64;
}

bool IsKnown(DataType type) {
  return FixedSize(type).has_value() || IsVariableLength(type);
}

bool IsReadable(Access access) {
  return access != Access::kWo;
}
bool IsWritable(Access access) {
  return access != Access::kRo && access != Access::kConst;
}

std::string_view ToString(DataType type) {
  switch (type) {
    case DataType::kBoolean:
      return "BOOLEAN";
    case DataType::kInteger8:
      return "INTEGER8";
    case DataType::kInteger16:
      return "INTEGER16";
    case DataType::kInteger24:
      return "INTEGER24";
    case DataType::kInteger32:
      return "INTEGER32";
    case DataType::kInteger40:
      return "INTEGER40";
    case DataType::kInteger48:
      return "INTEGER48";
    case DataType::kInteger56:
      return "INTEGER56";
    case DataType::kInteger64:
      return "INTEGER64";
    case DataType::kUnsigned8:
      return "UNSIGNED8";
    case DataType::kUnsigned16:
      return "UNSIGNED16";
    case DataType::kUnsigned24:
      return "UNSIGNED24";
    case DataType::kUnsigned32:
      return "UNSIGNED32";
    case DataType::kUnsigned40:
      return "UNSIGNED40";
    case DataType::kUnsigned48:
      return "UNSIGNED48";
    case DataType::kUnsigned56:
      return "UNSIGNED56";
    case DataType::kUnsigned64:
      return "UNSIGNED64";
    case DataType::kReal32:
      return "REAL32";
    case DataType::kReal64:
      return "REAL64";
    case DataType::kVisibleString:
      return "VISIBLE_STRING";
    case DataType::kOctetString:
      return "OCTET_STRING";
    case DataType::kUnicodeString:
      return "UNICODE_STRING";
    case DataType::kTimeOfDay:
      return "TIME_OF_DAY";
    case DataType::kTimeDifference:
      return "TIME_DIFFERENCE";
    case DataType::kDomain:
      return "DOMAIN";
  }
  return "UNKNOWN";
}

std::string_view ToString(Access access) {
  switch (access) {
    case Access::kRo:
      return "ro";
    case Access::kWo:
      return "wo";
    case Access::kRw:
      return "rw";
    case Access::kRwr:
      return "rwr";
    case Access::kRww:
      return "rww";
    case Access::kConst:
      return "const";
  }
  return "rw";
}

std::string_view ToString(ObjectCode code) {
  switch (code) {
    case ObjectCode::kNull:
      return "NULL";
    case ObjectCode::kDomain:
      return "DOMAIN";
    case ObjectCode::kDefType:
      return "DEFTYPE";
    case ObjectCode::kDefStruct:
      return "DEFSTRUCT";
    case ObjectCode::kVar:
      return "VAR";
    case ObjectCode::kArray:
      return "ARRAY";
    case ObjectCode::kRecord:
      return "RECORD";
  }
  return "VAR";
}

std::optional<Access> ParseAccess(std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  for (Access a : {Access::kRo, Access::kWo, Access::kRw, Access::kRwr, Access::kRww, Access::kConst}) {
    if (lower == ToString(a)) return a;
  }
  return std::nullopt;
}

}  // namespace canfleet::canopen
