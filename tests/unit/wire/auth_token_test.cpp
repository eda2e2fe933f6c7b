// The fleet's token and its preamble (bus/wire/auth_token.hpp): encoding, recognising a preamble
// among a protocol's first bytes, the constant-time comparison, and where a token comes from.
#include "bus/wire/auth_token.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

namespace canfleet::wire {
namespace {

std::vector<std::uint8_t> Bytes(std::string_view text) {
  return {text.begin(), text.end()};
}

TEST(AuthPreamble, EncodesMagicLengthAndToken) {
  const std::string token = "0123456789abcdef0123";
  const auto preamble = EncodeAuthPreamble(token);
  EXPECT_EQ(preamble.substr(0, 8), "CFAUTH1 ");
  EXPECT_EQ(static_cast<unsigned char>(preamble[8]), token.size());
  EXPECT_EQ(preamble.substr(9), token);
}

TEST(AuthPreamble, ScanFindsAWholePreambleAndWhereTheProtocolStarts) {
  const std::string token = "0123456789abcdef";
  const auto bytes = Bytes(EncodeAuthPreamble(token) + "\x05rest");
  const auto scan = ScanAuthPreamble(bytes);
  ASSERT_EQ(scan.kind, PreambleScan::Kind::kComplete);
  EXPECT_EQ(scan.size, 9 + token.size());
  EXPECT_EQ(scan.token, token);
}

TEST(AuthPreamble, ScanWaitsForTheRestOfAPreamble) {
  const auto whole = EncodeAuthPreamble("0123456789abcdef");
  for (std::size_t n : {1u, 2u, 7u, 8u, 9u, 20u}) {
    const auto bytes = Bytes(std::string_view(whole).substr(0, n));
    EXPECT_EQ(ScanAuthPreamble(bytes).kind, PreambleScan::Kind::kPartial) << n << " bytes";
  }
}

TEST(AuthPreamble, AProtocolMessageIsNoPreamble) {
  // A delimited protobuf message: a varint length, then a tag. "C" alone could be a length of 67,
  // so only the second byte tells: "CF..." is never protobuf (wire type 6).
  EXPECT_EQ(ScanAuthPreamble(Bytes("\x02\x0a\x00")).kind, PreambleScan::Kind::kNone);
  EXPECT_EQ(ScanAuthPreamble(Bytes("C\x0a")).kind, PreambleScan::Kind::kNone);
  EXPECT_EQ(ScanAuthPreamble(Bytes("CFAUTH2 ")).kind, PreambleScan::Kind::kNone);
  EXPECT_EQ(ScanAuthPreamble(Bytes("GET / HTTP/1.1\r\n")).kind, PreambleScan::Kind::kNone);
}

TEST(AuthPreamble, ATokenLengthOutsideTheRangeIsMalformed) {
  std::string bytes = "CFAUTH1 ";
  bytes.push_back(static_cast<char>(kMinTokenLength - 1));
  bytes += std::string(kMinTokenLength - 1, 'x');
  EXPECT_EQ(ScanAuthPreamble(Bytes(bytes)).kind, PreambleScan::Kind::kMalformed);
}

TEST(TokensEqual, EqualOnlyForTheSameBytesAndLength) {
  EXPECT_TRUE(TokensEqual("0123456789abcdef", "0123456789abcdef"));
  EXPECT_FALSE(TokensEqual("0123456789abcdef", "0123456789abcdeF"));
  EXPECT_FALSE(TokensEqual("0123456789abcdef", "X123456789abcdef"));
  EXPECT_FALSE(TokensEqual("0123456789abcdef", "0123456789abcde"));
  EXPECT_FALSE(TokensEqual("0123456789abcdef", "0123456789abcdef0"));
  EXPECT_FALSE(TokensEqual("0123456789abcdef", ""));
  // A given token padded with zero bytes is not the expected one either.
  EXPECT_FALSE(TokensEqual("0123456789abcdef", std::string("0123456789abcdef\0", 17)));
}

TEST(TokenProblem, LengthAndCharacters) {
  EXPECT_EQ(TokenProblem("0123456789abcdef"), "");
  EXPECT_NE(TokenProblem("short"), "");
  EXPECT_NE(TokenProblem(std::string(256, 'a')), "");
  EXPECT_NE(TokenProblem("0123456789 abcdef"), "");
  EXPECT_NE(TokenProblem("0123456789abcdef\x7f"), "");
}

TEST(GenerateToken, Random128BitsInHex) {
  const std::string a = GenerateToken(), b = GenerateToken();
  EXPECT_EQ(a.size(), 32u);
  EXPECT_NE(a, b);
  EXPECT_EQ(a.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_EQ(TokenProblem(a), "");
}

class TokenSources : public ::testing::Test {
 protected:
  void SetUp() override {
    ::unsetenv("CANFLEET_TOKEN_FILE");
    ::unsetenv("CANFLEET_TOKEN");
    dir_ = std::filesystem::temp_directory_path() / ("canfleet-token-test-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    ::unsetenv("CANFLEET_TOKEN_FILE");
    ::unsetenv("CANFLEET_TOKEN");
    std::filesystem::remove_all(dir_);
  }
  std::string Write(const std::string& name, const std::string& content) {
    const auto path = dir_ / name;
    std::ofstream(path) << content;
    return path.string();
  }
  std::filesystem::path dir_;
};

TEST_F(TokenSources, NoneSetIsNone) {
  EXPECT_EQ(ResolveToken(), std::nullopt);
}

TEST_F(TokenSources, AFileGivenWinsOverTheEnvironment) {
  const auto given = Write("given", "given-token-0123456789\n");
  const auto env_file = Write("env", "env-file-token-0123456789\n");
  ::setenv("CANFLEET_TOKEN_FILE", env_file.c_str(), 1);
  ::setenv("CANFLEET_TOKEN", "env-value-token-0123456789", 1);
  EXPECT_EQ(ResolveToken(given), "given-token-0123456789");
  EXPECT_EQ(ResolveToken(), "env-file-token-0123456789");
  ::unsetenv("CANFLEET_TOKEN_FILE");
  EXPECT_EQ(ResolveToken(), "env-value-token-0123456789");
}

TEST_F(TokenSources, AFileGivesItsFirstLineTrimmed) {
  EXPECT_EQ(ReadTokenFile(Write("t", "  0123456789abcdef \r\nsecond line\n")), "0123456789abcdef");
}

TEST_F(TokenSources, ProblemsNameTheFileOrTheVariable) {
  auto message = [](auto f) {
    try {
      f();
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const auto missing = (dir_ / "missing").string();
  EXPECT_NE(message([&] { ReadTokenFile(missing); }).find(missing), std::string::npos);
  const auto empty = Write("empty", "\n");
  EXPECT_NE(message([&] { ReadTokenFile(empty); }).find("empty"), std::string::npos);
  const auto short_one = Write("short", "abc\n");
  EXPECT_NE(message([&] { ReadTokenFile(short_one); }).find(short_one), std::string::npos);
  ::setenv("CANFLEET_TOKEN", "too short", 1);
  EXPECT_NE(message([] { ResolveToken(); }).find("CANFLEET_TOKEN"), std::string::npos);
}

}  // namespace
}  // namespace canfleet::wire
