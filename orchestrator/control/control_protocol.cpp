#include "orchestrator/control/control_protocol.hpp"

#include <stdexcept>

#include "bus/wire/varint.hpp"

namespace canfleet::control {

wire::Endpoint ParseControlEndpoint(std::string_view text) {
  wire::Endpoint ep = wire::Endpoint::Parse(text);
  if (ep.kind != wire::Endpoint::Kind::kTcp)
    throw std::invalid_argument("endpoint \"" + std::string(text) +
                                "\": the control API speaks TCP only (expected tcp://host:port)");
  return ep;
}

bool AppendDelimited(const google::protobuf::MessageLite& message, std::string& out, std::size_t max_size) {
  const std::size_t size = message.ByteSizeLong();
  if (size > max_size) return false;
  const std::size_t start = out.size();
  out.resize(start + wire::VarintSize(size) + size);
  auto* at = reinterpret_cast<std::uint8_t*>(out.data() + start);
  at = wire::WriteVarint(size, at);
  message.SerializeWithCachedSizesToArray(at);
  return true;
}

void DelimitedReader::Append(std::span<const std::uint8_t> bytes) {
  if (failed_) return;
  // Drop what was consumed before growing, so a long-lived stream does not grow without bound.
  if (begin_ != 0 && begin_ == buffer_.size()) {
    buffer_.clear();
    begin_ = 0;
  } else if (begin_ > 64 * 1024 && begin_ * 2 > buffer_.size()) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(begin_));
    begin_ = 0;
  }
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
}

DelimitedReader::Result DelimitedReader::Next(google::protobuf::MessageLite& out) {
  if (failed_) return Result::kError;
  const std::span<const std::uint8_t> pending(buffer_.data() + begin_, buffer_.size() - begin_);
  std::uint64_t size = 0;
  std::size_t prefix = 0;
  switch (wire::ReadVarint(pending, size, prefix)) {
    case wire::VarintStatus::kIncomplete:
      return Result::kNeedMore;
    case wire::VarintStatus::kOverlong:
      return Fail("malformed length prefix (varint longer than 10 bytes)");
    case wire::VarintStatus::kOk:
      break;
  }
  if (size > max_size_)
    return Fail("message of " + std::to_string(size) + " bytes exceeds the limit of " +
                std::to_string(max_size_));
  if (pending.size() - prefix < size) return Result::kNeedMore;
  out.Clear();
  if (!out.ParseFromArray(pending.data() + prefix, static_cast<int>(size)))
    return Fail("a message of " + std::to_string(size) + " bytes does not parse as " + out.GetTypeName());
  begin_ += prefix + static_cast<std::size_t>(size);
  return Result::kMessage;
}

DelimitedReader::Result DelimitedReader::Fail(std::string reason) {
  failed_ = true;
  error_ = std::move(reason);
  buffer_.clear();
  begin_ = 0;
  return Result::kError;
}

}  // namespace canfleet::control
