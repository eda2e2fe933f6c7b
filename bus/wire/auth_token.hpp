#pragma once
/// @file The fleet's shared secret: how a client proves it may drive or join a fleet that listens
/// beyond loopback (the control API, the broker's node port), and where the secret comes from.
///
/// A client that has a token sends it first on a TCP connection, before its protocol's first
/// message, as the auth preamble:
///
///     offset size
///          0    8  "CFAUTH1 " (43h 46h 41h 55h 54h 48h 31h 20h)
///          8    1  token length L, kMinTokenLength..kMaxTokenLength
///          9    L  the token (printable ASCII)
///
/// Both protocols on these ports are varint-length-delimited protobuf messages, and no such
/// stream starts with "CF": 43h is a length of 67 and the message's first byte 46h would be a tag
/// of wire type 6, which protobuf does not have. So a server can tell a preamble from a client
/// without one by its first bytes, and a client with a token can talk to a loopback server that
/// asks for none. The server's side is wire/auth_gate.hpp.
///
/// Where the token comes from (clients and servers alike): the file given on the command line
/// (--token-file), else the file named by CANFLEET_TOKEN_FILE (a Docker secret:
/// /run/secrets/canfleet_token), else CANFLEET_TOKEN itself. Never a plain command-line value:
/// that is visible to every user of the host in `ps`.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace canfleet::wire {

inline constexpr std::string_view kAuthMagic = "CFAUTH1 ";
inline constexpr std::size_t kMinTokenLength = 16;
inline constexpr std::size_t kMaxTokenLength = 255;
/// The longest preamble: magic, length byte, token.
inline constexpr std::size_t kMaxAuthPreamble = 8 + 1 + kMaxTokenLength;

/// The preamble carrying `token` (which must be valid: see TokenProblem).
std::string EncodeAuthPreamble(std::string_view token);

/// What the first bytes of a connection are.
struct PreambleScan {
  enum class Kind : std::uint8_t {
    kNone,      ///< not a preamble: the client's protocol starts here
    kPartial,   ///< the start of a preamble: wait for more bytes
    kComplete,  ///< a whole preamble of `size` bytes carrying `token`
    kMalformed  ///< the magic with a token length outside the allowed range
  };
  Kind kind = Kind::kNone;
  std::size_t size = 0;
  std::string_view token{};  ///< points into the scanned bytes (kComplete)
};
PreambleScan ScanAuthPreamble(std::span<const std::uint8_t> first_bytes);

/// Compares in time that depends on `expected`'s length only, never on where the first
/// difference is, so that timing tells an attacker nothing about the token.
bool TokensEqual(std::string_view expected, std::string_view given);

/// Why `token` cannot be used ("" if it can): kMinTokenLength..kMaxTokenLength printable ASCII
/// characters without spaces.
std::string TokenProblem(std::string_view token);

/// Reads a token file: its first line, without surrounding white space. Throws
/// std::runtime_error naming the file and what is wrong (missing, unreadable, empty, invalid).
std::string ReadTokenFile(const std::string& path);

/// The token from `token_file` if not empty, else from CANFLEET_TOKEN_FILE, else CANFLEET_TOKEN;
/// nullopt when none is set. Throws std::runtime_error as ReadTokenFile does, or naming the
/// variable whose value is invalid.
std::optional<std::string> ResolveToken(const std::string& token_file = {});

/// A new random token: 32 hexadecimal digits (128 bits from std::random_device).
std::string GenerateToken();

}  // namespace canfleet::wire
