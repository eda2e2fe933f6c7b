#include "tests/support/wire_text.hpp"

#include <cstdint>
#include <string_view>

namespace canfleet::test {
namespace {

/// Appends "name: value" fields separated by spaces, skipping proto3 defaults as protobuf does.
class TextBuilder {
 public:
  TextBuilder& Uint(std::string_view name, std::uint64_t v) {
    if (v != 0) Field(name, std::to_string(v));
    return *this;
  }
  TextBuilder& Bool(std::string_view name, bool v) {
    if (v) Field(name, "true");
    return *this;
  }
  TextBuilder& Enum(std::string_view name, int v, const std::string& text) {
    if (v != 0) Field(name, text);
    return *this;
  }
  TextBuilder& String(std::string_view name, const std::string& v) {
    if (!v.empty()) Field(name, Quoted(v));
    return *this;
  }
  TextBuilder& Message(std::string_view name, const std::string& body) {
    if (!text_.empty()) text_ += ' ';
    text_.append(name).append(" { ").append(body).append(body.empty() ? "}" : " }");
    return *this;
  }
  std::string Take() { return std::move(text_); }

 private:
  void Field(std::string_view name, const std::string& value) {
    if (!text_.empty()) text_ += ' ';
    text_.append(name).append(": ").append(value);
  }
  static std::string Quoted(const std::string& v) {
    std::string out = "\"";
    for (char c : v) {
      if (c == '"' || c == '\\') out += '\\';
      out += c;
    }
    return out + "\"";
  }
  std::string text_;
};

std::string IoValueText(const wire::IoValue& v) {
  return TextBuilder()
      .String("name", v.name())
      .String("value", v.value())
      .String("unit", v.unit())
      .Bool("input", v.input())
      .Take();
}

}  // namespace

std::string WireText(const wire::Hello& m) {
  return TextBuilder()
      .Uint("protocol_version", m.protocol_version())
      .String("bus", m.bus())
      .String("node_name", m.node_name())
      .Uint("node_id", m.node_id())
      .Enum("role", m.role(), wire::Role_Name(m.role()))
      .Bool("tx_confirmations", m.tx_confirmations())
      .Uint("bitrate", m.bitrate())
      .Take();
}

std::string WireText(const wire::HelloReply& m) {
  return TextBuilder()
      .Bool("accepted", m.accepted())
      .String("reason", m.reason())
      .Uint("protocol_version", m.protocol_version())
      .Uint("bitrate", m.bitrate())
      .Enum("mode", m.mode(), wire::BusMode_Name(m.mode()))
      .Uint("port_id", m.port_id())
      .Take();
}

std::string WireText(const wire::NodeRequest& m) {
  TextBuilder text;
  text.Uint("request_id", m.request_id());
  if (m.has_io_set())
    text.Message("io_set",
                 TextBuilder().String("name", m.io_set().name()).String("value", m.io_set().value()).Take());
  if (m.has_io_get()) text.Message("io_get", TextBuilder().String("name", m.io_get().name()).Take());
  return text.Take();
}

std::string WireText(const wire::NodeReply& m) {
  TextBuilder text;
  text.Uint("request_id", m.request_id()).String("error", m.error());
  for (const auto& v : m.values())
    text.Message("values", IoValueText(v));
  return text.Take();
}

}  // namespace canfleet::test
