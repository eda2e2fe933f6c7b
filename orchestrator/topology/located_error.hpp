#pragma once
/// @file Errors that say where: every refusal of a topology file names the file, the line and
/// column, and the path of the field ("node[2].node_id"). Internal to the loader.

#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/message.h>
#include <google/protobuf/text_format.h>

#include <string>
#include <string_view>
#include <vector>

#include "orchestrator/topology/topology_warning.hpp"

namespace canfleet::topology::detail {

namespace pb = google::protobuf;
using Tree = pb::TextFormat::ParseInfoTree;

struct Loc {
  int line = 1;  // 1-based
  int column = 1;
};

/// "line 12", for messages that point at another place in the file.
std::string LineRef(const Loc& loc);

/// Where syntax errors go: the first one wins (the parser stops there anyway).
class FirstErrorCollector final : public pb::io::ErrorCollector {
 public:
  void AddError(int line, pb::io::ColumnNumber column, const std::string& message) override;
  bool error() const { return error_; }
  int line() const { return line_; }
  int column() const { return column_; }
  const std::string& message() const { return message_; }

 private:
  bool error_ = false;
  int line_ = 0;
  int column_ = 0;
  std::string message_;
};

/// One message of the parsed file: its path ("node[2].heartbeat"), where it starts, and its parse
/// info tree (null when the text did not spell it out). Everything needed to name a field in an
/// error.
class Scope {
 public:
  /// @param warnings where Note appends (null: notes are dropped)
  Scope(const std::string* file, const pb::Message* message, const Tree* tree, std::string path, Loc loc,
        std::vector<TopologyWarning>* warnings = nullptr)
      : file_(file), message_(message), tree_(tree), path_(std::move(path)), loc_(loc), warnings_(warnings) {}

  Loc loc() const { return loc_; }
  const std::string& path() const { return path_; }

  /// Where the index-th value of `field` is (-1 or any index for a singular field); the scope's own
  /// start when the text does not have it. Values written as a list ("node_id: [5, 6]") share one
  /// location: a missing index falls back to the nearest earlier one.
  Loc At(std::string_view field, int index = -1) const;
  /// "node[2].node_id"; a repeated field's index is shown unless it holds a single scalar.
  std::string PathOf(std::string_view field, int index = -1) const;
  /// The scope of a nested message held by `field` (its index-th value when repeated).
  Scope Child(std::string_view field, const pb::Message& child, int index = -1) const;

  /// Throws the TopologyError "FILE:LINE:COL: PATH.field[index]: reason".
  [[noreturn]] void Fail(std::string_view field, int index, std::string reason) const;
  [[noreturn]] void Fail(std::string_view field, std::string reason) const {
    Fail(field, -1, std::move(reason));
  }
  /// An error about the message as a whole (a missing field is named by the caller's reason).
  [[noreturn]] void FailHere(std::string reason) const;
  /// Accepts the file but says something about it while it is checked: appends Warn(field,
  /// reason) to the loader's warnings (LoadedTopology::warnings), e.g. an old signal name.
  void Note(std::string_view field, std::string reason) const;

  /// A warning located as Fail() locates an error: the index-th value of `field`.
  TopologyWarning Warn(std::string_view field, int index, std::string reason) const;
  TopologyWarning Warn(std::string_view field, std::string reason) const {
    return Warn(field, -1, std::move(reason));
  }
  /// A warning about the message as a whole.
  TopologyWarning WarnHere(std::string reason) const;

 private:
  const pb::FieldDescriptor* Field(std::string_view name) const;

  const std::string* file_;
  const pb::Message* message_;
  const Tree* tree_;
  std::string path_;
  Loc loc_;
  std::vector<TopologyWarning>* warnings_;
};

}  // namespace canfleet::topology::detail
