#pragma once
/// @file CiA 305 v3.0.0 LSS wire format: CAN-IDs, command specifiers, error codes and the CiA 301
/// bit timing table. Shared by the slave and by test masters.
///
/// Every LSS frame has DLC 8; byte 0 is the command specifier (cs), unused bytes are 0:
///
///     byte  0    1        2        3  4  5  6  7
///           cs | service-specific data, little-endian |
///
/// Figure numbers below are those of CiA 305 v3.0.0 (as cited by lely-core `src/co/lss.c`).

#include <array>
#include <cstdint>
#include <optional>

#include "bus/can_frame.hpp"

namespace canfleet::canopen {

/// LSS master → slaves. Both LSS COB-IDs are fixed by CiA 305, independent of any node-ID.
inline constexpr std::uint32_t kLssMasterToSlaveId = 0x7E5;
/// LSS slave → master.
inline constexpr std::uint32_t kLssSlaveToMasterId = 0x7E4;
/// The node-ID of a slave without one ("non-configured" in CiA 305).
inline constexpr std::uint8_t kLssUnconfigured = 0xFF;

/// Command specifiers (byte 0).
enum class LssCs : std::uint8_t {
  kSwitchStateGlobal = 0x04,          ///< fig. 31; b1 = LssModeRequest; no reply
  kConfigureNodeId = 0x11,            ///< fig. 33; b1 = node-ID; reply b1 error, b2 spec error
  kConfigureBitTiming = 0x13,         ///< fig. 34; b1 table selector, b2 table index; reply b1 error, b2 spec
  kActivateBitTiming = 0x15,          ///< fig. 35; b1–2 switch delay (ms); no reply
  kStoreConfiguration = 0x17,         ///< fig. 36; reply b1 error, b2 spec error
  kSwitchSelectiveVendor = 0x40,      ///< fig. 32; b1–4 vendor-ID
  kSwitchSelectiveProduct = 0x41,     ///< b1–4 product code
  kSwitchSelectiveRevision = 0x42,    ///< b1–4 revision number
  kSwitchSelectiveSerial = 0x43,      ///< b1–4 serial number
  kSwitchSelectiveResponse = 0x44,    ///< slave: all four parts matched, now in configuration
  kIdentifyRemoteVendor = 0x46,       ///< fig. 42; b1–4 vendor-ID (exact)
  kIdentifyRemoteProduct = 0x47,      ///< b1–4 product code (exact)
  kIdentifyRemoteRevisionLow = 0x48,  ///< b1–4 lowest revision (inclusive)
  kIdentifyRemoteRevisionHigh = 0x49,  ///< b1–4 highest revision (inclusive)
  kIdentifyRemoteSerialLow = 0x4A,     ///< b1–4 lowest serial (inclusive)
  kIdentifyRemoteSerialHigh = 0x4B,    ///< b1–4 highest serial (inclusive)
  kIdentifyNonConfigured = 0x4C,       ///< fig. 44
  kIdentifySlave = 0x4F,               ///< slave: fig. 43 reply to identify remote slave and Fastscan
  kIdentifyNonConfiguredSlave = 0x50,  ///< slave: fig. 45 reply to 4Ch
  kFastscan = 0x51,                    ///< fig. 46; b1–4 IDNumber, b5 BitChecked, b6 LSSSub, b7 LSSNext
  kInquireVendor = 0x5A,               ///< fig. 37; reply b1–4
  kInquireProduct = 0x5B,              ///< fig. 38
  kInquireRevision = 0x5C,             ///< fig. 39
  kInquireSerial = 0x5D,               ///< fig. 40
  kInquireNodeId = 0x5E,               ///< fig. 41; reply b1 = active node-ID
};

/// Byte 1 of switch state global.
enum class LssModeRequest : std::uint8_t { kWaiting = 0, kConfiguration = 1 };

/// Error codes of configure node-ID (11h), configure bit timing (13h) and store configuration (17h).
inline constexpr std::uint8_t kLssOk = 0;
inline constexpr std::uint8_t kLssOutOfRange = 1;    ///< 11h: node-ID invalid; 13h: bit timing not supported
inline constexpr std::uint8_t kLssNotSupported = 1;  ///< 17h: storing is not supported
inline constexpr std::uint8_t kLssStorageError = 2;  ///< 17h: storage media access error

/// Fastscan BitChecked value that resets every non-configured slave's scan position (fig. 46).
inline constexpr std::uint8_t kFastscanReset = 0x80;

/// CiA 305 bit timing table 0 (the CiA 301 table), index → kbit/s. Index 5 is reserved and index
/// 9 is automatic bit rate detection; both are "not supported" here (nullopt).
std::optional<std::uint32_t> BitRateKbit(std::uint8_t table_index);

/// An LSS frame on `id` with command specifier `cs` and up to seven data bytes (rest 0, DLC 8).
CanFrame LssFrame(std::uint32_t id, LssCs cs, std::initializer_list<std::uint8_t> data = {});
/// An LSS frame carrying a little-endian 32-bit value in bytes 1–4.
CanFrame LssFrame32(std::uint32_t id, LssCs cs, std::uint32_t value);

}  // namespace canfleet::canopen
