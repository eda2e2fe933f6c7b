// PrintJson: a response body as JSON for scripts and jq. Protobuf's own JSON mapping writes 64-bit
// integers as strings (counters such as BusStatus.frames), so this walks the message by reflection
// instead: every number is a JSON number; otherwise the same mapping (field names as in the
// .proto, every field even when zero, enums by name, bytes in base64, NaN/Infinity as strings).
#include <google/protobuf/descriptor.h>

#include <charconv>
#include <cmath>
#include <iostream>
#include <string>

#include "tools/canfleet/cli.hpp"
#include "tools/telemetry/event_format.hpp"

namespace canfleet::cli {

namespace {

namespace pb = google::protobuf;

// One JSON string escaping for the CLI and the telemetry tools (canfleet watch --json).
std::string Quoted(std::string_view text) {
  return tools::JsonString(text);
}

std::string Base64(std::string_view bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) |
                       (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out +=
        {kAlphabet[(v >> 18) & 63], kAlphabet[(v >> 12) & 63], kAlphabet[(v >> 6) & 63], kAlphabet[v & 63]};
  }
  if (const std::size_t rest = bytes.size() - i; rest > 0) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (rest == 2) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string Real(double value) {
  if (std::isnan(value)) return "\"NaN\"";
  if (std::isinf(value)) return value > 0 ? "\"Infinity\"" : "\"-Infinity\"";
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, end);
}

class JsonWriter {
 public:
  explicit JsonWriter(bool one_line) : one_line_(one_line) {}

  void Message(const pb::Message& message, int depth) {
    const pb::Descriptor* descriptor = message.GetDescriptor();
    const pb::Reflection* reflection = message.GetReflection();
    out_ += '{';
    bool first = true;
    for (int i = 0; i < descriptor->field_count(); ++i) {
      const pb::FieldDescriptor* field = descriptor->field(i);
      // Like protobuf's always_print_primitive_fields: a message field or a oneof member shows only
      // when set, every other field always.
      const bool shown = field->is_repeated() ? true
                         : (field->cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE ||
                            field->containing_oneof() != nullptr || field->has_presence())
                             ? reflection->HasField(message, field)
                             : true;
      if (!shown) continue;
      out_ += first ? "" : ",";
      first = false;
      Newline(depth + 1);
      out_ += Quoted(field->name());
      out_ += one_line_ ? ":" : ": ";
      if (field->is_repeated()) {
        const int n = reflection->FieldSize(message, field);
        out_ += '[';
        for (int k = 0; k < n; ++k) {
          if (k > 0) out_ += ',';
          Newline(depth + 2);
          Value(message, field, k, depth + 2);
        }
        if (n > 0) Newline(depth + 1);
        out_ += ']';
      } else {
        Value(message, field, -1, depth + 1);
      }
    }
    if (!first) Newline(depth);
    out_ += '}';
  }

  std::string Take() { return std::move(out_); }

 private:
  void Newline(int depth) {
    if (one_line_) return;
    out_ += '\n';
    out_.append(static_cast<std::size_t>(depth), ' ');
  }

  /// One value of `field` (index -1: a singular field).
  void Value(const pb::Message& m, const pb::FieldDescriptor* f, int index, int depth) {
    const pb::Reflection* r = m.GetReflection();
    const bool rep = index >= 0;
    switch (f->cpp_type()) {
      case pb::FieldDescriptor::CPPTYPE_INT32:
        out_ += std::to_string(rep ? r->GetRepeatedInt32(m, f, index) : r->GetInt32(m, f));
        break;
      case pb::FieldDescriptor::CPPTYPE_INT64:
        out_ += std::to_string(rep ? r->GetRepeatedInt64(m, f, index) : r->GetInt64(m, f));
        break;
      case pb::FieldDescriptor::CPPTYPE_UINT32:
        out_ += std::to_string(rep ? r->GetRepeatedUInt32(m, f, index) : r->GetUInt32(m, f));
        break;
      case pb::FieldDescriptor::CPPTYPE_UINT64:
        out_ += std::to_string(rep ? r->GetRepeatedUInt64(m, f, index) : r->GetUInt64(m, f));
        break;
      case pb::FieldDescriptor::CPPTYPE_DOUBLE:
        out_ += Real(rep ? r->GetRepeatedDouble(m, f, index) : r->GetDouble(m, f));
        break;
      case pb::FieldDescriptor::CPPTYPE_FLOAT:
        out_ += Real(rep ? r->GetRepeatedFloat(m, f, index) : r->GetFloat(m, f));
        break;
      case pb::FieldDescriptor::CPPTYPE_BOOL:
        out_ += (rep ? r->GetRepeatedBool(m, f, index) : r->GetBool(m, f)) ? "true" : "false";
        break;
      case pb::FieldDescriptor::CPPTYPE_ENUM: {
        const pb::EnumValueDescriptor* e = rep ? r->GetRepeatedEnum(m, f, index) : r->GetEnum(m, f);
        out_ += Quoted(e->name());
        break;
      }
      case pb::FieldDescriptor::CPPTYPE_STRING: {
        const std::string s = rep ? r->GetRepeatedString(m, f, index) : r->GetString(m, f);
        out_ += f->type() == pb::FieldDescriptor::TYPE_BYTES ? Quoted(Base64(s)) : Quoted(s);
        break;
      }
      case pb::FieldDescriptor::CPPTYPE_MESSAGE:
        Message(rep ? r->GetRepeatedMessage(m, f, index) : r->GetMessage(m, f), depth);
        break;
    }
  }

  bool one_line_;
  std::string out_;
};

}  // namespace

std::string ToJson(const google::protobuf::Message& message, bool one_line) {
  JsonWriter writer(one_line);
  writer.Message(message, 0);
  return writer.Take();
}

void PrintJson(const google::protobuf::Message& message, bool one_line) {
  std::cout << ToJson(message, one_line) << '\n';
}

}  // namespace canfleet::cli
