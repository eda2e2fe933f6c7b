#pragma once
/// @file A write-only file with a user-space buffer: the capture writers' one way to the disk.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace canfleet::capture {

class CaptureFile {
 public:
  /// Bytes gathered before a write(2) (a capture of a busy bus writes in large blocks).
  static constexpr std::size_t kBufferSize = 64 * 1024;

  /// Creates or truncates `path`. Throws std::system_error when it cannot be opened (an edge:
  /// the caller asked for a file it cannot have).
  explicit CaptureFile(const std::filesystem::path& path);
  ~CaptureFile();
  CaptureFile(const CaptureFile&) = delete;
  CaptureFile& operator=(const CaptureFile&) = delete;

  /// Appends bytes; writes the buffer out when it is full. Ignored once closed or failed.
  void Append(std::span<const std::uint8_t> bytes);
  void Append(std::string_view text) {
    Append(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  }
  void Flush();
  /// Flushes and closes; further appends are ignored. Safe to call twice.
  void Close();

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  void Fail(int errnum);

  std::filesystem::path path_;
  int fd_ = -1;
  std::vector<std::uint8_t> buffer_;
  std::string error_;
};

}  // namespace canfleet::capture
