#pragma once
/// @file The object dictionary (CiA 301 §7.4): objects, their sub-objects, and access-checked
/// reads and writes with hooks through which services and device code compute values and veto or
/// react to writes.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "node/canopen/od/abort_code.hpp"
#include "node/canopen/od/small_bytes.hpp"
#include "node/canopen/od/types.hpp"
#include "node/canopen/od/value.hpp"

namespace canfleet::canopen {

/// Who is asking. SDO requests obey access types, limits and validators; RPDOs write mapped
/// objects (mappability is checked when the mapping is made); the device itself bypasses access
/// types, limits and validators (it writes its own read-only inputs) but listeners still run.
enum class Origin : std::uint8_t { kSdo, kPdo, kDevice };

struct SubObject;

/// Called before a value is read; may refresh `sub.value` or refuse with an abort code
/// (e.g. 1003h beyond the current number of errors answers kNoData).
using ReadHook = std::function<SdoAbort(SubObject& sub, Origin origin)>;
/// Called before a write is committed, after type/length/limit checks; returns kNone to accept.
using WriteValidator =
    std::function<SdoAbort(const SubObject& sub, std::span<const std::uint8_t> data, Origin origin)>;
/// Called after a write was committed.
using WriteListener = std::function<void(SubObject& sub, Origin origin)>;

/// The hooks of one sub-object. Most sub-objects have none, so they live in their own allocation,
/// made when the first is added (idle RSS, bench/idle/README.md).
struct SubObjectHooks {
  std::vector<ReadHook> read_hooks;
  std::vector<WriteValidator> validators;
  std::vector<WriteListener> listeners;
};

/// One sub-index of an object (a VAR object has exactly one, at sub-index 0).
struct SubObject {
  // Small fields first, packed: a valve controller has 2500 sub-objects.
  std::uint16_t index = 0;
  std::uint8_t sub_index = 0;
  Access access = Access::kRw;
  DataType type = DataType::kUnsigned8;
  bool pdo_mappable = false;
  bool default_adds_node_id = false;  ///< EDS "$NODEID+x": the node-ID is added when applied
  std::uint32_t obj_flags = 0;        ///< CiA 306 ObjFlags, kept for round trips
  std::string name;
  std::optional<SmallBytes> low_limit;   ///< encoded like the value
  std::optional<SmallBytes> high_limit;  ///< encoded like the value
  SmallBytes default_value;              ///< encoded; node-ID not yet added (see default_adds_node_id)
  SmallBytes value;                      ///< the current value, encoded

  SubObject() = default;
  SubObject(const SubObject& other);
  SubObject(SubObject&&) noexcept = default;
  SubObject& operator=(const SubObject& other);
  SubObject& operator=(SubObject&&) noexcept = default;
  ~SubObject() = default;

  /// Computes or refreshes the value before each read; runs in the order added.
  void AddReadHook(ReadHook hook);
  /// Vetoes a write (SDO and PDO origins); runs in the order added.
  void AddValidator(WriteValidator validator);
  /// Reacts after a committed write; runs in the order added, before the dictionary's listeners.
  void AddListener(WriteListener listener);
  std::span<const ReadHook> read_hooks() const;
  std::span<const WriteValidator> validators() const;
  std::span<const WriteListener> listeners() const;

  /// The default with the node-ID applied, encoded like the value.
  Bytes DefaultFor(std::uint8_t node_id) const;
  /// Size in bits for PDO mapping (8 × byte size for fixed types, 0 for variable-length types).
  std::uint32_t BitLength() const;

 private:
  std::unique_ptr<SubObjectHooks> hooks_;  ///< null until a hook is added
};

/// A sub-object with its current value set to its default (sub-index and index are filled in
/// by ObjectDictionary::Add).
SubObject MakeSubObject(std::string name, DataType type, Access access, Bytes default_value,
                        bool pdo_mappable = false);

/// One object: VAR, ARRAY or RECORD (DOMAIN/DEFTYPE/DEFSTRUCT are kept for EDS round trips).
struct Object {
  std::uint16_t index = 0;
  std::string name;
  ObjectCode code = ObjectCode::kVar;
  std::uint32_t obj_flags = 0;
  std::uint8_t compact_sub_obj = 0;  ///< CiA 306 CompactSubObj as read (0 = expanded)
  std::map<std::uint8_t, SubObject> subs;
};

/// A whole dictionary. Objects and sub-objects never move once added, so services may keep
/// pointers to them (the PDO path resolves its mapping to SubObject pointers once).
class ObjectDictionary {
 public:
  using Objects = std::map<std::uint16_t, Object>;

  /// Adds or replaces an object. Sub-objects get `index` filled in.
  Object& Add(Object object);
  /// Adds a VAR object in one call (common in tests and device code).
  SubObject& AddVar(std::uint16_t index, std::string name, DataType type, Access access, Bytes default_value,
                    bool pdo_mappable = false);

  Object* Find(std::uint16_t index);
  const Object* Find(std::uint16_t index) const;
  SubObject* Find(std::uint16_t index, std::uint8_t sub);
  const SubObject* Find(std::uint16_t index, std::uint8_t sub) const;

  /// Finds a sub-object, or says which abort code a client gets: kNoObject or kNoSubIndex.
  SdoAbort Lookup(std::uint16_t index, std::uint8_t sub, SubObject*& out);

  /// Reads a value on behalf of `origin`: existence, access (kWriteOnly) and read hooks.
  SdoAbort Read(std::uint16_t index, std::uint8_t sub, Bytes& out, Origin origin = Origin::kSdo);
  /// Writes a value on behalf of `origin`: existence, access (kReadOnly), length (kLengthTooHigh/Low),
  /// limits (kValueTooHigh/Low), BOOLEAN range, validators; then commits and runs listeners.
  SdoAbort Write(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data,
                 Origin origin = Origin::kSdo);
  /// The same checks as Write for an already-resolved sub-object (the hot path of RPDOs).
  SdoAbort Write(SubObject& sub, std::span<const std::uint8_t> data, Origin origin);

  /// Device-side typed access. Get returns 0 for a missing entry; Set writes with Origin::kDevice.
  std::uint64_t GetUnsigned(std::uint16_t index, std::uint8_t sub) const;
  std::int64_t GetSigned(std::uint16_t index, std::uint8_t sub) const;
  SdoAbort SetUnsigned(std::uint16_t index, std::uint8_t sub, std::uint64_t value);
  SdoAbort SetSigned(std::uint16_t index, std::uint8_t sub, std::int64_t value);

  /// Restores the defaults of every object with index in [first, last] (reset node: 1000h–FFFFh;
  /// reset communication: 1000h–1FFFh), applying `node_id` to "$NODEID" defaults. Listeners run.
  /// Borrowed objects are left alone: their owner restores them.
  void RestoreDefaults(std::uint16_t first, std::uint16_t last, std::uint8_t node_id);

  /// Adds a listener that runs after every committed write through this dictionary, to any
  /// sub-object (borrowed ones too), after the sub-object's own listeners; RestoreDefaults runs it
  /// for every value it changes. For reactions to "any write" (waking a device's application):
  /// one listener instead of one per sub-object. A device with borrowed objects adds it to each
  /// dictionary that serves them.
  void AddWriteListener(WriteListener listener) { write_listeners_.push_back(std::move(listener)); }

  /// Serves `object`, owned by another dictionary, at its index (replacing an own object there):
  /// one object seen through two dictionaries, as the application objects of a device with two
  /// CAN ports (data logger UMAX181001 §1.1: "2 CAN interfaces which share manufacturer-specific
  /// objects"). Find, Lookup, Read and Write reach it; objects(), RestoreDefaults and therefore
  /// storage (ParameterStore) do not: they are the owner's, so a reset or a restore of this
  /// dictionary never touches the shared values. The owner must outlive this dictionary.
  void Borrow(Object& object);
  bool IsBorrowed(std::uint16_t index) const { return borrowed_.contains(index); }

  /// The objects this dictionary owns (borrowed ones are not listed).
  const Objects& objects() const { return objects_; }
  Objects& objects() { return objects_; }

 private:
  void Committed(SubObject& sub, Origin origin);

  Objects objects_;
  std::map<std::uint16_t, Object*> borrowed_;
  std::vector<WriteListener> write_listeners_;
};

}  // namespace canfleet::canopen
