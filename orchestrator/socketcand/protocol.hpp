#pragma once
/// @file The socketcand protocol (https://github.com/linux-can/socketcand, doc/protocol.md), the
/// part a raw-mode client uses: splitting the byte stream into `< ... >` elements, parsing the
/// client's commands and formatting what the server sends. Pure functions, no I/O.
///
/// A session, as socketcand runs it:
///
///     server: < hi >
///     client: < open can0 >        server: < ok >   (unknown bus: < error could not open bus >, close)
///     client: < rawmode >          server: < ok >
///     server: < frame 123 1700000000.123456 DEADBEEF >      every frame on the bus
///     server: < frame 1ABCDEF0 1700000000.123789 00 >       29-bit id: always 8 hex digits
///     server: < rtr 705 1700000000.124000 1 >               remote frame (doc/protocol.md)
///     client: < send 181 3 DE AD 5 >                        DLC decimal, bytes hex (1-2 digits)
///     client: < send 00000181 0 >                           8 id digits: a 29-bit identifier
///     client: < sendrtr 705 1 >                             remote frame
///     client: < echo >             server: < echo >

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "bus/can_frame.hpp"
#include "clock/wall_clock.hpp"

namespace canfleet::socketcand {

/// socketcand's default TCP port.
inline constexpr std::uint16_t kDefaultPort = 29536;
/// Longest element accepted from a client, '<' to '>' inclusive. The longest valid command,
/// "< send 1FFFFFFF 8 FF FF FF FF FF FF FF FF >", has 43 bytes; socketcand's bus names have at
/// most 16 characters.
inline constexpr std::size_t kMaxElementLength = 256;
inline constexpr std::size_t kMaxBusNameLength = 16;
/// Frame messages are padded to this size in aligned mode (see AppendFrame).
inline constexpr std::size_t kAlignedRecordSize = 64;

/// Wall-clock time (Unix epoch) of a frame, as socketcand prints its kernel timestamps
/// (clock/wall_clock.hpp).
using canfleet::WallTime;

/// Splits what a client sends into elements, like socketcand's receive_command: bytes before a
/// '<' are garbage and dropped, an element runs from '<' to the next '>' (a second '<' before it
/// restarts the element: the first was garbage). Memory is bounded: an element longer than
/// kMaxElementLength is an error (the session closes the connection).
class ElementReader {
 public:
  enum class Status : std::uint8_t { kElement, kNeedMore, kTooLong };
  struct Result {
    Status status = Status::kNeedMore;
    std::string_view element;  ///< kElement: the text from '<' to '>', valid until the next Feed
  };

  void Feed(std::string_view bytes);
  /// The next complete element, if any.
  Result Next();
  /// Bytes held (incomplete element, or elements not taken yet).
  std::size_t Buffered() const { return buffer_.size() - pos_; }
  std::uint64_t DiscardedBytes() const { return discarded_; }

 private:
  std::string buffer_;
  std::size_t pos_ = 0;  ///< start of what has not been taken
  std::uint64_t discarded_ = 0;
};

enum class CommandKind : std::uint8_t {
  kOpen,         ///< < open NAME >
  kRawMode,      ///< < rawmode >
  kBcmMode,      ///< < bcmmode >
  kIsotpMode,    ///< < isotpmode >   (not served)
  kControlMode,  ///< < controlmode > (not served)
  kEcho,         ///< < echo >
  kSend,         ///< < send ID DLC B0 .. Bn >
  kSendRtr,      ///< < sendrtr ID DLC >
  kBcmCommand,   ///< add, update, delete, filter, muxfilter, subscribe, unsubscribe (not served)
  kBusConfig,    ///< < can0 B ... >, < can0 C ... > (bit timing / control mode; not served)
  kUnknown,      ///< a command word socketcand does not know
  kMalformed,    ///< a known command with bad arguments; `error` says what is wrong
};

struct Command {
  CommandKind kind = CommandKind::kUnknown;
  /// kOpen: the bus name; kBcmCommand/kUnknown: the command word; kBusConfig: the bus name.
  std::string_view argument;
  CanFrame frame;          ///< kSend, kSendRtr: a valid frame
  const char* error = "";  ///< kMalformed: why
};

/// Parses one element ("< ... >", as ElementReader returns it). Fields are separated by any ASCII
/// whitespace. Identifiers are 1..8 hex digits; like socketcand, 8 digits mean a 29-bit
/// identifier. Unlike socketcand, a value above 0x7FF written with fewer digits is taken as a
/// 29-bit identifier too instead of being truncated (python-can 4.1.0 writes extended ids
/// without leading zeros). The DLC is decimal 0..8, followed by exactly DLC bytes of 1-2 hex
/// digits (socketcand's "%hhu" and "%hhx").
Command ParseCommand(std::string_view element);

/// Appends the message socketcand sends for a frame received in raw mode:
///   data frame:   "< frame ID SEC.USEC DATA >"  (ID %03X or %08X, DATA contiguous %02X, may be
///                 empty: "< frame 123 1700000000.000000  >" as socketcand prints it)
///   remote frame: "< rtr ID SEC.USEC DLC >"
/// Error frames are not sent (socketcand's raw socket does not subscribe to them); returns false
/// for them and appends nothing.
///
/// `aligned`: the message is preceded by spaces so that it fills a multiple of
/// kAlignedRecordSize bytes. A client that scans for '<' and '>' (every socketcand client)
/// ignores the spaces; python-can 4.1.0, which loses a message split across two of its
/// 1024-byte recv() calls, then never sees one split while every write is a whole number of
/// 64-byte records (1024 is a multiple of 64; a split inside the padding is harmless).
bool AppendFrame(std::string& out, const CanFrame& frame, WallTime time, bool aligned);

/// Appends `message` ("< echo >"...), padded like AppendFrame when `aligned`.
void AppendMessage(std::string& out, std::string_view message, bool aligned);

/// Formats a frame as a client's send command ("< send 123 2 DE AD >", "< sendrtr 705 1 >"),
/// for tests and tools. Ids: %03X / %08X, bytes %02X.
std::string FormatSend(const CanFrame& frame);

}  // namespace canfleet::socketcand
