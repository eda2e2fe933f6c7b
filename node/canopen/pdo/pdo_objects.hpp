#pragma once
/// @file The PDO objects of CiA 301 v4.2: RPDO communication (1400h–15FFh, §7.5.2.35) and mapping
/// (1600h–17FFh, §7.5.2.36) parameters, TPDO communication (1800h–19FFh, §7.5.2.37) and mapping
/// (1A00h–1BFFh, §7.5.2.38) parameters.
///
/// Communication parameter record:
///   sub0 U8  highest sub-index (5 for an RPDO, 6 for a TPDO)
///   sub1 U32 COB-ID: bit 31 1 = PDO not valid; bit 30 1 = no RTR allowed; bit 29 1 = 29-bit
///            CAN-ID; bits 28-11 0 for an 11-bit CAN-ID; bits 10-0 (or 28-0) CAN-ID
///   sub2 U8  transmission type: 0 synchronous acyclic, 1–240 every n-th SYNC, 241–251 reserved,
///            252 synchronous RTR-only, 253 event RTR-only, 254/255 event-driven
///   sub3 U16 inhibit time, 100 µs
///   sub4 U8  reserved (compatibility entry)
///   sub5 U16 event timer, ms (TPDO: longest gap between transmissions; RPDO: reception deadline)
///   sub6 U8  SYNC start value, 0–240 (TPDO only)
/// Mapping parameter record:
///   sub0 U8  number of mapped objects (0–64)
///   subN U32 index << 16 | sub-index << 8 | length in bits

#include <cstddef>
#include <cstdint>

#include "node/canopen/od/object_dictionary.hpp"

namespace canfleet::canopen {

inline constexpr std::uint16_t kRpdoCommBase = 0x1400;
inline constexpr std::uint16_t kRpdoMappingBase = 0x1600;
inline constexpr std::uint16_t kTpdoCommBase = 0x1800;
inline constexpr std::uint16_t kTpdoMappingBase = 0x1A00;
/// Comm and mapping records come in blocks of 512 (1400h–15FFh, 1600h–17FFh...).
inline constexpr std::size_t kMaxPdos = 512;
/// Offset from a communication record to its mapping record.
inline constexpr std::uint16_t kMappingOffset = 0x200;
/// Mapping entries per record that AddPdoObjects creates (one per byte of a classical frame).
inline constexpr std::uint8_t kDefaultMappingEntries = 8;
/// CiA 301 §7.5.2.36: at most 64 objects (64 one-bit objects fill one frame).
inline constexpr std::uint8_t kMaxMappingEntries = 64;

/// COB-ID bits of sub1 (CiA 301 §7.5.2.35).
inline constexpr std::uint32_t kPdoCobIdInvalid = 0x80000000;
inline constexpr std::uint32_t kPdoCobIdNoRtr = 0x40000000;
inline constexpr std::uint32_t kPdoCobIdFrame = 0x20000000;

/// Transmission types (CiA 301 §7.5.2.35 and §7.5.2.37).
inline constexpr std::uint8_t kTransmissionSyncAcyclic = 0;
inline constexpr std::uint8_t kTransmissionSyncMaxCycle = 240;
inline constexpr std::uint8_t kTransmissionRtrSync = 252;
inline constexpr std::uint8_t kTransmissionRtrEvent = 253;
inline constexpr std::uint8_t kTransmissionEventManufacturer = 254;
inline constexpr std::uint8_t kTransmissionEventProfile = 255;

/// Adds `rpdos` RPDOs and `tpdos` TPDOs (each at most 512) with their CiA 301 default
/// communication and mapping records.
///
/// - PDOs 1–4 use the pre-defined connection set (CiA 301, facts §1): RPDOn COB-ID
///   40000000h + 200h/300h/400h/500h + $NODEID, TPDOn 40000000h + 180h/280h/380h/480h + $NODEID
///   (valid, no RTR); further PDOs default to 80000000h (not valid, no CAN-ID).
/// - Transmission type 255, inhibit time 0, event timer 0, SYNC start value 0.
/// - Mapping: sub0 = 0 and 8 entries of 0, all rw. Nothing is mapped, so a valid PDO sends nothing
///   until a mapping is configured.
/// The comm records carry the node-ID relative default ("$NODEID"): call
/// ObjectDictionary::RestoreDefaults with the node-ID to apply it.
void AddPdoObjects(ObjectDictionary& od, std::size_t rpdos, std::size_t tpdos);

}  // namespace canfleet::canopen
