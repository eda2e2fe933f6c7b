#include "orchestrator/topology/located_error.hpp"

#include <algorithm>
#include <stdexcept>

#include "orchestrator/topology/topology_loader.hpp"

namespace canfleet::topology {

namespace {

std::string FormatMessage(const std::string& file, int line, int column, const std::string& field,
                          const std::string& reason) {
  std::string out = file;
  if (line > 0) out += ":" + std::to_string(line) + ":" + std::to_string(column);
  out += ": ";
  if (!field.empty()) out += field + ": ";
  return out + reason;
}

}  // namespace

TopologyError::TopologyError(std::string file, int line, int column, std::string field, std::string reason)
    : std::runtime_error(FormatMessage(file, line, column, field, reason)),
      file_(std::move(file)),
      line_(line),
      column_(column),
      field_(std::move(field)),
      reason_(std::move(reason)) {}

namespace detail {

std::string LineRef(const Loc& loc) {
  return "line " + std::to_string(loc.line);
}

void FirstErrorCollector::AddError(int line, pb::io::ColumnNumber column, const std::string& message) {
  if (error_) return;
  error_ = true;
  line_ = line + 1;
  column_ = column + 1;
  message_ = message;
}

Loc Scope::At(std::string_view field, int index) const {
  const pb::FieldDescriptor* fd = Field(field);
  if (tree_ == nullptr) return loc_;
  if (!fd->is_repeated()) {
    const auto l = tree_->GetLocation(fd, -1);
    return l.line >= 0 ? Loc{l.line + 1, l.column + 1} : loc_;
  }
  for (int i = std::max(index, 0); i >= 0; --i) {
    const auto l = tree_->GetLocation(fd, i);
    if (l.line >= 0) return {l.line + 1, l.column + 1};
  }
  return loc_;
}

std::string Scope::PathOf(std::string_view field, int index) const {
  std::string out = path_.empty() ? std::string(field) : path_ + "." + std::string(field);
  const pb::FieldDescriptor* fd = Field(field);
  if (fd->is_repeated() && index >= 0) {
    const bool single_scalar = fd->cpp_type() != pb::FieldDescriptor::CPPTYPE_MESSAGE &&
                               message_->GetReflection()->FieldSize(*message_, fd) == 1;
    if (!single_scalar) out += "[" + std::to_string(index) + "]";
  }
  return out;
}

Scope Scope::Child(std::string_view field, const pb::Message& child, int index) const {
  const pb::FieldDescriptor* fd = Field(field);
  const Tree* nested = nullptr;
  if (tree_ != nullptr) nested = tree_->GetTreeForNested(fd, fd->is_repeated() ? std::max(index, 0) : -1);
  std::string path = path_.empty() ? std::string(field) : path_ + "." + std::string(field);
  if (fd->is_repeated()) path += "[" + std::to_string(std::max(index, 0)) + "]";
  return Scope(file_, &child, nested, std::move(path), At(field, index), warnings_);
}

void Scope::Fail(std::string_view field, int index, std::string reason) const {
  const Loc l = At(field, index);
  throw TopologyError(*file_, l.line, l.column, PathOf(field, index), std::move(reason));
}

void Scope::Note(std::string_view field, std::string reason) const {
  if (warnings_ != nullptr) warnings_->push_back(Warn(field, std::move(reason)));
}

void Scope::FailHere(std::string reason) const {
  throw TopologyError(*file_, loc_.line, loc_.column, path_.empty() ? "topology" : path_, std::move(reason));
}

TopologyWarning Scope::Warn(std::string_view field, int index, std::string reason) const {
  const Loc l = At(field, index);
  return TopologyWarning{*file_, l.line, l.column, PathOf(field, index), std::move(reason)};
}

TopologyWarning Scope::WarnHere(std::string reason) const {
  return TopologyWarning{*file_, loc_.line, loc_.column, path_.empty() ? "topology" : path_,
                         std::move(reason)};
}

const pb::FieldDescriptor* Scope::Field(std::string_view name) const {
  const pb::FieldDescriptor* fd = message_->GetDescriptor()->FindFieldByName(std::string(name));
  if (fd == nullptr) throw std::logic_error("topology loader: no field " + std::string(name));
  return fd;
}

}  // namespace detail
}  // namespace canfleet::topology
