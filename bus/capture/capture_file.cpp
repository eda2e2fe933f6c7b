#include "bus/capture/capture_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

namespace canfleet::capture {

CaptureFile::CaptureFile(const std::filesystem::path& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw std::system_error(errno, std::generic_category(), "cannot open capture " + path.string());
  buffer_.reserve(kBufferSize);
}

CaptureFile::~CaptureFile() {
  Close();
}

void CaptureFile::Append(std::span<const std::uint8_t> bytes) {
  if (fd_ < 0) return;
  if (buffer_.size() + bytes.size() > kBufferSize) Flush();
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
}

void CaptureFile::Flush() {
  if (fd_ < 0) return;
  std::size_t done = 0;
  while (done < buffer_.size()) {
    const ssize_t n = ::write(fd_, buffer_.data() + done, buffer_.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      Fail(errno);
      return;
    }
    done += static_cast<std::size_t>(n);
  }
  buffer_.clear();
}

void CaptureFile::Close() {
  if (fd_ < 0) return;
  Flush();
  if (fd_ >= 0 && ::close(fd_) != 0 && ok()) error_ = path_.string() + ": close: " + std::strerror(errno);
  fd_ = -1;
}

void CaptureFile::Fail(int errnum) {
  error_ = path_.string() + ": write: " + std::strerror(errnum);
  ::close(fd_);
  fd_ = -1;
  buffer_.clear();
}

}  // namespace canfleet::capture
