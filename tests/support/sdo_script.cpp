#include "tests/support/sdo_script.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace canfleet::test {

namespace {

std::string Cob(std::uint32_t id) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%03X#", static_cast<unsigned>(id));
  return buf;
}

std::string Multiplexer(std::uint16_t index, std::uint8_t sub) {
  return LeHex(index, 2) + LeHex(sub, 1);
}

}  // namespace

std::string LeHex(std::uint64_t value, int size) {
  std::string out;
  char buf[4];
  for (int i = 0; i < size; ++i) {
    std::snprintf(buf, sizeof buf, "%02X", static_cast<unsigned>((value >> (8 * i)) & 0xFF));
    out += buf;
  }
  return out;
}

std::string SdoDownload(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint64_t value,
                        int size) {
  static const char* kCommand[] = {"", "2F", "2B", "27", "23"};
  return Cob(0x600u + node) + kCommand[size] + Multiplexer(index, sub) + LeHex(value, size) +
         std::string(static_cast<std::size_t>(2 * (4 - size)), '0');
}

std::string SdoDownloaded(std::uint8_t node, std::uint16_t index, std::uint8_t sub) {
  return Cob(0x580u + node) + "60" + Multiplexer(index, sub) + "00000000";
}

std::string SdoAbortFrom(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t code) {
  return Cob(0x580u + node) + "80" + Multiplexer(index, sub) + LeHex(code, 4);
}

std::string SdoUpload(std::uint8_t node, std::uint16_t index, std::uint8_t sub) {
  return Cob(0x600u + node) + "40" + Multiplexer(index, sub) + "00000000";
}

std::vector<std::string> TakeFrames(BusProbe& probe, std::deque<std::string>& backlog) {
  std::vector<std::string> out(backlog.begin(), backlog.end());
  backlog.clear();
  for (auto& f : probe.Take())
    out.push_back(std::move(f));
  return out;
}

std::vector<std::string> TakeFrames(BusProbe& probe, std::deque<std::string>& backlog,
                                    std::string_view prefix) {
  std::vector<std::string> out;
  for (auto& f : TakeFrames(probe, backlog)) {
    if (f.starts_with(prefix)) out.push_back(std::move(f));
  }
  return out;
}

std::string ExchangeSdo(BusProbe& probe, std::deque<std::string>& backlog, std::uint8_t node,
                        std::string_view request) {
  for (auto& f : probe.Take())
    backlog.push_back(std::move(f));
  probe.Send(request);
  const std::string answer_prefix = Cob(0x580u + node);
  std::string answer;
  for (auto& f : probe.Take()) {
    if (answer.empty() && f.starts_with(answer_prefix))
      answer = std::move(f);
    else
      backlog.push_back(std::move(f));
  }
  return answer;
}

std::int64_t ExpeditedValue(const std::string& answer, bool is_signed) {
  // "585#4Bxxxxss" + data: 4F 1 byte, 4B 2, 47 3, 43 4.
  EXPECT_EQ(answer.size(), 4u + 16u) << answer;
  if (answer.size() != 20) return 0;
  const std::string cmd = answer.substr(4, 2);
  const int size = cmd == "4F" ? 1 : cmd == "4B" ? 2 : cmd == "47" ? 3 : cmd == "43" ? 4 : 0;
  EXPECT_NE(size, 0) << answer;
  std::uint64_t value = 0;
  for (int i = 0; i < size; ++i)
    value |= std::stoull(answer.substr(static_cast<std::size_t>(12 + 2 * i), 2), nullptr, 16) << (8 * i);
  if (is_signed && size > 0 && size < 8 && ((value >> (8 * size - 1)) & 1))
    value |= ~std::uint64_t{0} << (8 * size);
  return static_cast<std::int64_t>(value);
}

}  // namespace canfleet::test
