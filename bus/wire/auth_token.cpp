#include "bus/wire/auth_token.hpp"

#include <cstdlib>
#include <fstream>
#include <random>
#include <stdexcept>

namespace canfleet::wire {

std::string EncodeAuthPreamble(std::string_view token) {
  std::string out(kAuthMagic);
  out.push_back(static_cast<char>(token.size()));
  out.append(token);
  return out;
}

PreambleScan ScanAuthPreamble(std::span<const std::uint8_t> first_bytes) {
  const std::size_t magic_seen = std::min(first_bytes.size(), kAuthMagic.size());
  for (std::size_t i = 0; i < magic_seen; ++i) {
    if (first_bytes[i] != static_cast<std::uint8_t>(kAuthMagic[i])) return {};
  }
  if (first_bytes.size() <= kAuthMagic.size()) return {PreambleScan::Kind::kPartial};
  const std::size_t length = first_bytes[kAuthMagic.size()];
  if (length < kMinTokenLength) return {PreambleScan::Kind::kMalformed};
  const std::size_t size = kAuthMagic.size() + 1 + length;
  if (first_bytes.size() < size) return {PreambleScan::Kind::kPartial};
  const auto* token = reinterpret_cast<const char*>(first_bytes.data()) + kAuthMagic.size() + 1;
  return {PreambleScan::Kind::kComplete, size, std::string_view(token, length)};
}

bool TokensEqual(std::string_view expected, std::string_view given) {
  // Every byte of `expected` is compared (with a byte of `given`, or 0 past its end) and the
  // differences are OR-ed together: no early exit, no branch on the data.
  unsigned diff = expected.size() == given.size() ? 0u : 1u;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const auto g = i < given.size() ? static_cast<unsigned char>(given[i]) : 0u;
    diff |= static_cast<unsigned char>(expected[i]) ^ g;
  }
  return diff == 0;
}

std::string TokenProblem(std::string_view token) {
  if (token.size() < kMinTokenLength || token.size() > kMaxTokenLength)
    return "a token has " + std::to_string(kMinTokenLength) + ".." + std::to_string(kMaxTokenLength) +
           " characters, this one " + std::to_string(token.size());
  for (const char c : token) {
    if (c <= ' ' || c > '~') return "a token is printable ASCII without spaces";
  }
  return {};
}

namespace {

std::string Trimmed(std::string text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

}  // namespace

std::string ReadTokenFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("token file " + path + ": cannot be read (missing, or no permission)");
  std::string line;
  std::getline(in, line);
  line = Trimmed(std::move(line));
  if (line.empty()) throw std::runtime_error("token file " + path + ": its first line is empty");
  if (const auto problem = TokenProblem(line); !problem.empty())
    throw std::runtime_error("token file " + path + ": " + problem);
  return line;
}

std::optional<std::string> ResolveToken(const std::string& token_file) {
  if (!token_file.empty()) return ReadTokenFile(token_file);
  if (const char* file = std::getenv("CANFLEET_TOKEN_FILE"); file != nullptr && *file != '\0')
    return ReadTokenFile(file);
  if (const char* value = std::getenv("CANFLEET_TOKEN"); value != nullptr && *value != '\0') {
    std::string token = Trimmed(value);
    if (const auto problem = TokenProblem(token); !problem.empty())
      throw std::runtime_error("CANFLEET_TOKEN: " + problem);
    return token;
  }
  return std::nullopt;
}

std::string GenerateToken() {
  std::random_device random;
  static constexpr char kHex[] = "0123456789abcdef";
  std::string token;
  for (int word = 0; word < 4; ++word) {
    std::uint32_t bits = random();
    for (int nibble = 0; nibble < 8; ++nibble, bits >>= 4)
      token.push_back(kHex[bits & 0xF]);
  }
  return token;
}

}  // namespace canfleet::wire
