#pragma once
/// @file PDO mapping (CiA 301 v4.2 §7.5.2.36/§7.5.2.38): checking mapping entries and
/// moving mapped objects between the object dictionary and a frame.
///
/// Mapping entry, UNSIGNED32:  bits 31-16 index   bits 15-8 sub-index   bits 7-0 length in bits
/// Objects are packed in entry order from bit 0 of byte 0 upwards, each little-endian, so byte-sized
/// objects land on byte boundaries and smaller ones (BOOLEAN as 1 bit) share bytes.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "node/canopen/od/abort_code.hpp"
#include "node/canopen/od/object_dictionary.hpp"
#include "node/canopen/pdo/pdo_objects.hpp"

namespace canfleet::canopen {

/// RPDO (the network writes the mapped objects) or TPDO (the node reads them).
enum class PdoDirection : std::uint8_t { kReceive, kTransmit };

/// One resolved entry. `sub` is null for a dummy entry (RPDO only: received bits are dropped) and
/// for the empty entry 00000000h (0 bits), which device defaults use to pad unused entries.
struct MappedObject {
  SubObject* sub = nullptr;
  std::uint8_t offset = 0;  ///< first bit in the frame
  std::uint8_t length = 0;  ///< bits
  std::uint8_t size = 0;    ///< encoded size of the object in bytes
  bool is_signed = false;   ///< sign-extend when fewer bits than the object holds are mapped

  friend bool operator==(const MappedObject&, const MappedObject&) = default;
};

/// A mapping resolved to sub-objects once per configuration change, so that moving data between
/// frames and the dictionary needs no lookup and no allocation.
class PdoMapping {
 public:
  std::span<const MappedObject> Entries() const { return entries_; }
  /// Mapped length in bits (0..64) and in bytes (the PDO's DLC).
  std::uint32_t Bits() const { return bits_; }
  std::uint8_t Bytes() const { return static_cast<std::uint8_t>((bits_ + 7) / 8); }
  /// True if `sub` is one of the mapped objects.
  bool Maps(const SubObject& sub) const;

  /// TPDO: samples the mapped objects into `data` (bytes beyond Bytes() are 0). Read hooks run
  /// with Origin::kPdo; a hook's refusal leaves the stored value in use.
  void Pack(std::array<std::uint8_t, 8>& data) const;
  /// RPDO: writes each mapped object from `data` (at least Bytes() long) with
  /// ObjectDictionary::Write(..., Origin::kPdo), so limits, validators and listeners apply; a
  /// refused object keeps its value and the others are still written.
  void Unpack(ObjectDictionary& od, std::span<const std::uint8_t> data) const;

  void Clear();
  /// Appends an entry at the current end; false if it would exceed 64 bits.
  bool Append(MappedObject entry);

  friend bool operator==(const PdoMapping&, const PdoMapping&) = default;

 private:
  std::vector<MappedObject> entries_;
  std::uint32_t bits_ = 0;
};

/// Checks one mapping entry for a PDO of `direction` and describes it in `out` (offset 0).
/// - 00000000h: the empty entry, 0 bits (CANopenNode treats it as a 0-byte dummy).
/// - index 0001h–001Fh, sub-index 0, a fixed-size data type: a dummy entry (CiA 301 §7.4.7.1,
///   mapping of the data type objects) — RPDO only, for a TPDO kNotMappable (06040041h).
/// - otherwise the object must exist (kNoObject 06020000h / kNoSubIndex 06090011h), be
///   PDO-mappable, of a fixed-size type, writable (RPDO) or readable (TPDO) → else kNotMappable.
/// - length 1..8 × the object's size in bytes (BOOLEAN: 1..8) → else kNotMappable.
SdoAbort CheckMappingEntry(ObjectDictionary& od, PdoDirection direction, std::uint32_t entry,
                           MappedObject& out);

/// Resolves entries 1..`count` of a mapping record, as they are in the dictionary, into `out`.
/// `count` > 64 or a missing entry sub-index → kInvalidValue (06090030h); an entry error as
/// CheckMappingEntry; more than 64 bits in total → kPdoLengthExceeded (06040042h).
/// On error `out` holds the entries before the faulty one.
SdoAbort ResolveMapping(ObjectDictionary& od, PdoDirection direction, const Object& record,
                        std::uint8_t count, PdoMapping& out);

}  // namespace canfleet::canopen
