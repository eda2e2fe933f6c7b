#pragma once
/// @file Application objects shared by the stacks of a multi-port device. The data logger
/// (UMAX181001 §1.1) "supports 2 CAN interfaces which share manufacturer-specific objects but have
/// separate Communication Objects": each port has its own dictionary (its own 1000h–1FFFh, NMT
/// state, PDOs), and the application objects of both dictionaries behave as one.
///
/// The first dictionary is the primary: the device installs its hooks there and its blocks write
/// there. For every sub-object that both dictionaries hold in the shared range:
///  - a write to either (SDO, RPDO, device, RestoreDefaults) shows in the other, and the other's
///    listeners run, so a TPDO of either port sees the new value;
///  - a network write to the replica is checked by the primary's validators first (one rule set);
///  - a read of the replica runs the primary's read hooks and answers the primary's value.

#include <cstdint>
#include <unordered_map>

#include "node/canopen/od/object_dictionary.hpp"

namespace canfleet::devices {

class SharedObjects {
 public:
  /// Shares every sub-object in [first, last] present in both dictionaries (same index, sub-index
  /// and type). Both dictionaries must outlive this object, which must not move (hooks capture it).
  SharedObjects(canopen::ObjectDictionary& primary, canopen::ObjectDictionary& replica, std::uint16_t first,
                std::uint16_t last);
  SharedObjects(const SharedObjects&) = delete;
  SharedObjects& operator=(const SharedObjects&) = delete;

  /// The replica's copy of a shared primary sub-object (for the replica stack's PDO
  /// notifications), or null.
  canopen::SubObject* ReplicaOf(const canopen::SubObject& primary_sub) const;
  std::size_t Count() const { return pairs_.size(); }

 private:
  void Share(canopen::SubObject& primary, canopen::SubObject& replica);
  static void Copy(canopen::ObjectDictionary& to_od, canopen::SubObject& to, const canopen::SubObject& from);

  canopen::ObjectDictionary& primary_;
  canopen::ObjectDictionary& replica_;
  std::unordered_map<const canopen::SubObject*, canopen::SubObject*> pairs_;
};

}  // namespace canfleet::devices
