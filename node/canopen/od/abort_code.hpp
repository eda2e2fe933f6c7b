#pragma once
/// @file CiA 301 SDO abort codes (CiA 301 v4.2 §7.2.4.3.17, table 22). Abort codes are data: every
/// decision point in the stack returns the exact code, and SdoAbort::kNone means success.

#include <cstdint>

namespace canfleet::canopen {

enum class SdoAbort : std::uint32_t {
  kNone = 0,
  kToggleBit = 0x05030000,              ///< toggle bit not alternated
  kTimeout = 0x05040000,                ///< SDO protocol timed out
  kInvalidCommand = 0x05040001,         ///< client/server command specifier not valid or unknown
  kInvalidBlockSize = 0x05040002,       ///< invalid block size (block mode only)
  kInvalidSequence = 0x05040003,        ///< invalid sequence number (block mode only)
  kCrcError = 0x05040004,               ///< CRC error (block mode only)
  kOutOfMemory = 0x05040005,            ///< out of memory
  kUnsupportedAccess = 0x06010000,      ///< unsupported access to an object
  kWriteOnly = 0x06010001,              ///< attempt to read a write-only object
  kReadOnly = 0x06010002,               ///< attempt to write a read-only object
  kNoObject = 0x06020000,               ///< object does not exist in the object dictionary
  kNotMappable = 0x06040041,            ///< object cannot be mapped to the PDO
  kPdoLengthExceeded = 0x06040042,      ///< number and length of mapped objects exceed PDO length
  kParameterIncompatible = 0x06040043,  ///< general parameter incompatibility
  kInternalIncompatible = 0x06040047,   ///< general internal incompatibility in the device
  kHardwareError = 0x06060000,          ///< access failed due to a hardware error
  kTypeMismatch = 0x06070010,    ///< data type does not match, length of service parameter does not match
  kLengthTooHigh = 0x06070012,   ///< data type does not match, length of service parameter too high
  kLengthTooLow = 0x06070013,    ///< data type does not match, length of service parameter too low
  kNoSubIndex = 0x06090011,      ///< sub-index does not exist
  kInvalidValue = 0x06090030,    ///< invalid value for parameter (download only)
  kValueTooHigh = 0x06090031,    ///< value of parameter written too high (download only)
  kValueTooLow = 0x06090032,     ///< value of parameter written too low (download only)
  kMaxBelowMin = 0x06090036,     ///< maximum value is less than minimum value
  kNoResource = 0x060A0023,      ///< resource not available: SDO connection
  kGeneralError = 0x08000000,    ///< general error
  kCannotTransfer = 0x08000020,  ///< data cannot be transferred or stored to the application
  kLocalControl = 0x08000021,    ///< ... because of local control
  kDeviceState = 0x08000022,     ///< ... because of the present device state
  kNoDictionary = 0x08000023,    ///< object dictionary dynamic generation fails or no OD present
  kNoData = 0x08000024,          ///< no data available
};

/// The CiA 301 text of an abort code ("unknown abort code" for values outside the table).
const char* Describe(SdoAbort code);

}  // namespace canfleet::canopen
