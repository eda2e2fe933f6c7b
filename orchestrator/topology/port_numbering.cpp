#include "orchestrator/topology/port_numbering.hpp"

#include <string>

namespace canfleet::topology::detail {

namespace pb = google::protobuf;

namespace {

// The most ports a catalogued device has (the data logger's CAN1 and CAN2); whether the node has
// that many is checked with the node (expect_checks, node_checks).
constexpr std::uint32_t kMaxCanPorts = 2;

const pb::FieldDescriptor* UInt32Field(const pb::Message& message, const char* name) {
  const pb::FieldDescriptor* fd = message.GetDescriptor()->FindFieldByName(name);
  if (fd == nullptr || fd->is_repeated() || fd->cpp_type() != pb::FieldDescriptor::CPPTYPE_UINT32)
    return nullptr;
  return fd;
}

void NumberOne(const Scope& scope, pb::Message& message) {
  const pb::FieldDescriptor* can = UInt32Field(message, "can");
  const pb::FieldDescriptor* port = UInt32Field(message, "port");
  if (can == nullptr || port == nullptr) return;
  const pb::Reflection* r = message.GetReflection();
  const std::uint32_t can_value = r->GetUInt32(message, can);
  const std::uint32_t port_value = r->GetUInt32(message, port);
  if (can_value != 0) {
    if (port_value != 0)
      scope.Fail("port", "give the port once: can: " + std::to_string(can_value) +
                             " (as the manual prints it) replaces the deprecated port");
    if (can_value > kMaxCanPorts)
      scope.Fail("can", "CAN" + std::to_string(can_value) +
                            ": ports are numbered as the manuals print them, can: 1 (CAN1) or can: 2 (CAN2)");
    r->SetUInt32(&message, port, can_value - 1);
  } else if (port_value != 0) {
    scope.Note("port", "deprecated: port: " + std::to_string(port_value) +
                           " counts from 0; write can: " + std::to_string(port_value + 1) + " (" +
                           CanName(port_value) + ", as the manuals print the ports)");
  }
}

}  // namespace

void NumberPortsAsManuals(const Scope& scope, pb::Message& message) {
  NumberOne(scope, message);
  const pb::Descriptor* d = message.GetDescriptor();
  const pb::Reflection* r = message.GetReflection();
  for (int i = 0; i < d->field_count(); ++i) {
    const pb::FieldDescriptor* fd = d->field(i);
    if (fd->cpp_type() != pb::FieldDescriptor::CPPTYPE_MESSAGE) continue;
    const std::string name(fd->name());
    if (fd->is_repeated()) {
      for (int j = 0; j < r->FieldSize(message, fd); ++j) {
        pb::Message* child = r->MutableRepeatedMessage(&message, fd, j);
        NumberPortsAsManuals(scope.Child(name, *child, j), *child);
      }
    } else if (r->HasField(message, fd)) {
      pb::Message* child = r->MutableMessage(&message, fd);
      NumberPortsAsManuals(scope.Child(name, *child), *child);
    }
  }
}

const char* PortFieldName(const pb::Message& message) {
  const pb::FieldDescriptor* can = UInt32Field(message, "can");
  if (can != nullptr && message.GetReflection()->GetUInt32(message, can) != 0) return "can";
  return "port";
}

std::string CanName(std::uint32_t port) {
  return "CAN" + std::to_string(port + 1);
}

}  // namespace canfleet::topology::detail
