#include "node/canopen/od/object_dictionary.hpp"

namespace canfleet::canopen {

Bytes SubObject::DefaultFor(std::uint8_t node_id) const {
  if (!default_adds_node_id || IsVariableLength(type)) return Bytes(default_value);
  auto size = default_value.size();
  if (IsSigned(type)) return EncodeLe(DecodeSignedLe(default_value) + node_id, size);
  return EncodeLe(DecodeUnsignedLe(default_value) + node_id, size);
}

SubObject::SubObject(const SubObject& other)
    : index(other.index),
      sub_index(other.sub_index),
      access(other.access),
      type(other.type),
      pdo_mappable(other.pdo_mappable),
      default_adds_node_id(other.default_adds_node_id),
      obj_flags(other.obj_flags),
      name(other.name),
      low_limit(other.low_limit),
      high_limit(other.high_limit),
      default_value(other.default_value),
      value(other.value),
      hooks_(other.hooks_ ? std::make_unique<SubObjectHooks>(*other.hooks_) : nullptr) {}

SubObject& SubObject::operator=(const SubObject& other) {
  if (this != &other) *this = SubObject(other);
  return *this;
}

void SubObject::AddReadHook(ReadHook hook) {
  if (!hooks_) hooks_ = std::make_unique<SubObjectHooks>();
  hooks_->read_hooks.push_back(std::move(hook));
}

void SubObject::AddValidator(WriteValidator validator) {
  if (!hooks_) hooks_ = std::make_unique<SubObjectHooks>();
  hooks_->validators.push_back(std::move(validator));
}

void SubObject::AddListener(WriteListener listener) {
  if (!hooks_) hooks_ = std::make_unique<SubObjectHooks>();
  hooks_->listeners.push_back(std::move(listener));
}

std::span<const ReadHook> SubObject::read_hooks() const {
  return hooks_ ? std::span<const ReadHook>(hooks_->read_hooks) : std::span<const ReadHook>();
}

std::span<const WriteValidator> SubObject::validators() const {
  return hooks_ ? std::span<const WriteValidator>(hooks_->validators) : std::span<const WriteValidator>();
}

std::span<const WriteListener> SubObject::listeners() const {
  return hooks_ ? std::span<const WriteListener>(hooks_->listeners) : std::span<const WriteListener>();
}

std::uint32_t SubObject::BitLength() const {
  if (type == DataType::kBoolean) return 1;
  auto size = FixedSize(type);
  return size ? static_cast<std::uint32_t>(*size * 8) : 0;
}

SubObject MakeSubObject(std::string name, DataType type, Access access, Bytes default_value,
                        bool pdo_mappable) {
  SubObject sub;
  sub.name = std::move(name);
  sub.type = type;
  sub.access = access;
  sub.pdo_mappable = pdo_mappable;
  sub.default_value = default_value;
  sub.value = std::move(default_value);
  return sub;
}

Object& ObjectDictionary::Add(Object object) {
  for (auto& [sub_index, sub] : object.subs) {
    sub.index = object.index;
    sub.sub_index = sub_index;
    if (sub.value.empty()) sub.value = sub.default_value;
  }
  auto index = object.index;
  borrowed_.erase(index);
  objects_.insert_or_assign(index, std::move(object));
  return objects_.at(index);
}

SubObject& ObjectDictionary::AddVar(std::uint16_t index, std::string name, DataType type, Access access,
                                    Bytes default_value, bool pdo_mappable) {
  Object obj;
  obj.index = index;
  obj.name = name;  // copied: the sub-object takes the original
  obj.code = ObjectCode::kVar;
  obj.subs.emplace(0, MakeSubObject(std::move(name), type, access, std::move(default_value), pdo_mappable));
  return Add(std::move(obj)).subs.at(0);
}

Object* ObjectDictionary::Find(std::uint16_t index) {
  if (auto it = objects_.find(index); it != objects_.end()) return &it->second;
  auto it = borrowed_.find(index);
  return it == borrowed_.end() ? nullptr : it->second;
}

const Object* ObjectDictionary::Find(std::uint16_t index) const {
  if (auto it = objects_.find(index); it != objects_.end()) return &it->second;
  auto it = borrowed_.find(index);
  return it == borrowed_.end() ? nullptr : it->second;
}

void ObjectDictionary::Borrow(Object& object) {
  objects_.erase(object.index);
  borrowed_.insert_or_assign(object.index, &object);
}

SubObject* ObjectDictionary::Find(std::uint16_t index, std::uint8_t sub) {
  Object* obj = Find(index);
  if (!obj) return nullptr;
  auto it = obj->subs.find(sub);
  return it == obj->subs.end() ? nullptr : &it->second;
}

const SubObject* ObjectDictionary::Find(std::uint16_t index, std::uint8_t sub) const {
  const Object* obj = Find(index);
  if (!obj) return nullptr;
  auto it = obj->subs.find(sub);
  return it == obj->subs.end() ? nullptr : &it->second;
}

SdoAbort ObjectDictionary::Lookup(std::uint16_t index, std::uint8_t sub, SubObject*& out) {
  out = nullptr;
  Object* obj = Find(index);
  if (!obj) return SdoAbort::kNoObject;
  auto it = obj->subs.find(sub);
  if (it == obj->subs.end()) return SdoAbort::kNoSubIndex;
  out = &it->second;
  return SdoAbort::kNone;
}

SdoAbort ObjectDictionary::Read(std::uint16_t index, std::uint8_t sub_index, Bytes& out, Origin origin) {
  SubObject* sub = nullptr;
  if (auto rc = Lookup(index, sub_index, sub); rc != SdoAbort::kNone) return rc;
  if (origin == Origin::kSdo && !IsReadable(sub->access)) return SdoAbort::kWriteOnly;
  for (const auto& hook : sub->read_hooks()) {
    if (auto rc = hook(*sub, origin); rc != SdoAbort::kNone) return rc;
  }
  out = sub->value;
  return SdoAbort::kNone;
}

SdoAbort ObjectDictionary::Write(std::uint16_t index, std::uint8_t sub_index,
                                 std::span<const std::uint8_t> data, Origin origin) {
  SubObject* sub = nullptr;
  if (auto rc = Lookup(index, sub_index, sub); rc != SdoAbort::kNone) return rc;
  return Write(*sub, data, origin);
}

SdoAbort ObjectDictionary::Write(SubObject& sub, std::span<const std::uint8_t> data, Origin origin) {
  const bool checked = origin != Origin::kDevice;
  if (origin == Origin::kSdo && !IsWritable(sub.access)) return SdoAbort::kReadOnly;
  if (auto size = FixedSize(sub.type)) {
    if (data.size() > *size) return SdoAbort::kLengthTooHigh;
    if (data.size() < *size) return SdoAbort::kLengthTooLow;
  }
  if (checked) {
    if (sub.type == DataType::kBoolean && data[0] > 1) return SdoAbort::kInvalidValue;
    if (!IsVariableLength(sub.type)) {
      if (sub.high_limit && CompareNumeric(sub.type, data, *sub.high_limit) > 0)
        return SdoAbort::kValueTooHigh;
      if (sub.low_limit && CompareNumeric(sub.type, data, *sub.low_limit) < 0) return SdoAbort::kValueTooLow;
    }
    for (const auto& validate : sub.validators()) {
      if (auto rc = validate(sub, data, origin); rc != SdoAbort::kNone) return rc;
    }
  }
  // assign() reuses the existing buffer when the size does not grow: no allocation per RPDO.
  sub.value.assign(data.begin(), data.end());
  Committed(sub, origin);
  return SdoAbort::kNone;
}

void ObjectDictionary::Committed(SubObject& sub, Origin origin) {
  for (const auto& listener : sub.listeners())
    listener(sub, origin);
  for (const auto& listener : write_listeners_)
    listener(sub, origin);
}

std::uint64_t ObjectDictionary::GetUnsigned(std::uint16_t index, std::uint8_t sub) const {
  const SubObject* s = Find(index, sub);
  return s ? DecodeUnsignedLe(s->value) : 0;
}

std::int64_t ObjectDictionary::GetSigned(std::uint16_t index, std::uint8_t sub) const {
  const SubObject* s = Find(index, sub);
  return s ? DecodeSignedLe(s->value) : 0;
}

SdoAbort ObjectDictionary::SetUnsigned(std::uint16_t index, std::uint8_t sub_index, std::uint64_t value) {
  SubObject* sub = nullptr;
  if (auto rc = Lookup(index, sub_index, sub); rc != SdoAbort::kNone) return rc;
  auto bytes = EncodeLe(value, FixedSize(sub->type).value_or(8));
  return Write(*sub, bytes, Origin::kDevice);
}

SdoAbort ObjectDictionary::SetSigned(std::uint16_t index, std::uint8_t sub_index, std::int64_t value) {
  SubObject* sub = nullptr;
  if (auto rc = Lookup(index, sub_index, sub); rc != SdoAbort::kNone) return rc;
  auto bytes = EncodeLe(value, FixedSize(sub->type).value_or(8));
  return Write(*sub, bytes, Origin::kDevice);
}

void ObjectDictionary::RestoreDefaults(std::uint16_t first, std::uint16_t last, std::uint8_t node_id) {
  for (auto it = objects_.lower_bound(first); it != objects_.end() && it->first <= last; ++it) {
    for (auto& [sub_index, sub] : it->second.subs) {
      auto def = sub.DefaultFor(node_id);
      if (sub.value == def) continue;
      sub.value = def;
      Committed(sub, Origin::kDevice);
    }
  }
}

}  // namespace canfleet::canopen
