#pragma once
/// @file CANopen data types, object codes and access types with the numeric values of CiA 301
/// (table 44, data types) and CiA 306 (EDS ObjectType, AccessType).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace canfleet::canopen {

/// CiA 301 §7.4.7.1 data type indexes (the values EDS files use in DataType=).
enum class DataType : std::uint16_t {
  kBoolean = 0x0001,
  kInteger8 = 0x0002,
  kInteger16 = 0x0003,
  kInteger32 = 0x0004,
  kUnsigned8 = 0x0005,
  kUnsigned16 = 0x0006,
  kUnsigned32 = 0x0007,
  kReal32 = 0x0008,
  kVisibleString = 0x0009,
  kOctetString = 0x000A,
  kUnicodeString = 0x000B,
  kTimeOfDay = 0x000C,
  kTimeDifference = 0x000D,
  kDomain = 0x000F,
  kInteger24 = 0x0010,
  kReal64 = 0x0011,
  kInteger40 = 0x0012,
  kInteger48 = 0x0013,
  kInteger56 = 0x0014,
  kInteger64 = 0x0015,
  kUnsigned24 = 0x0016,
  kUnsigned40 = 0x0018,
  kUnsigned48 = 0x0019,
  kUnsigned56 = 0x001A,
  kUnsigned64 = 0x001B,
};

/// CiA 306 ObjectType values.
enum class ObjectCode : std::uint8_t {
  kNull = 0x0,
  kDomain = 0x2,
  kDefType = 0x5,
  kDefStruct = 0x6,
  kVar = 0x7,
  kArray = 0x8,
  kRecord = 0x9,
};

/// CiA 306 AccessType. rwr: read/write, mappable into a TPDO (the device updates it);
/// rww: read/write, mappable into an RPDO (the network updates it).
enum class Access : std::uint8_t { kRo, kWo, kRw, kRwr, kRww, kConst };

/// Encoded size in bytes of a fixed-size type; nullopt for strings and domains.
std::optional<std::size_t> FixedSize(DataType type);
/// True for the variable-length types (VISIBLE_STRING, OCTET_STRING, UNICODE_STRING, DOMAIN).
bool IsVariableLength(DataType type);
bool IsSigned(DataType type);    ///< INTEGERn
bool IsUnsigned(DataType type);  ///< UNSIGNEDn and BOOLEAN
bool IsReal(DataType type);      ///< REAL32, REAL64
/// True if the type is a known CiA 301 basic type that the stack can store.
bool IsKnown(DataType type);

bool IsReadable(Access access);  ///< by SDO
bool IsWritable(Access access);  ///< by SDO

std::string_view ToString(DataType type);    ///< "UNSIGNED16"
std::string_view ToString(Access access);    ///< EDS spelling: "ro", "rw", "const"...
std::string_view ToString(ObjectCode code);  ///< "VAR", "ARRAY", "RECORD"...
/// Parses the EDS spelling of an access type (case-insensitive).
std::optional<Access> ParseAccess(std::string_view text);

}  // namespace canfleet::canopen
