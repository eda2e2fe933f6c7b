#include "node/canopen/storage/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

namespace canfleet::canopen {

namespace {

std::error_code LastError() {
  return {errno, std::generic_category()};
}

/// Closes a descriptor on scope exit unless released (the success path closes explicitly to see
/// close's error, which can carry a deferred write error on some file systems).
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }
  std::error_code Close() {
    int fd = fd_;
    fd_ = -1;
    return ::close(fd) == 0 ? std::error_code{} : LastError();
  }

 private:
  int fd_;
};

std::error_code WriteAll(int fd, std::span<const std::uint8_t> bytes) {
  while (!bytes.empty()) {
    ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return LastError();
    }
    bytes = bytes.subspan(static_cast<std::size_t>(n));
  }
  return {};
}

}  // namespace

std::error_code SyncDirectory(const std::filesystem::path& dir) {
  Fd fd(::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (fd.get() < 0) return LastError();
  if (::fsync(fd.get()) != 0) return LastError();
  return fd.Close();
}

std::filesystem::path TempPathFor(const std::filesystem::path& path) {
  auto tmp = path;
  tmp += ".tmp";
  return tmp;
}

std::error_code WriteFileDurably(const std::filesystem::path& path, std::span<const std::uint8_t> bytes) {
  Fd fd(::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
  if (fd.get() < 0) return LastError();
  if (auto ec = WriteAll(fd.get(), bytes)) return ec;
  if (::fsync(fd.get()) != 0) return LastError();
  return fd.Close();
}

std::error_code RenameFile(const std::filesystem::path& from, const std::filesystem::path& to) {
  return ::rename(from.c_str(), to.c_str()) == 0 ? std::error_code{} : LastError();
}

std::error_code WriteFileAtomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes) {
  const auto dir = path.parent_path();
  std::error_code ec;
  if (!dir.empty()) {
    std::filesystem::create_directories(dir, ec);
    if (ec) return ec;
  }
  const auto tmp = TempPathFor(path);
  ec = WriteFileDurably(tmp, bytes);
  if (!ec) ec = RenameFile(tmp, path);
  if (ec) {
    ::unlink(tmp.c_str());  // best effort; a leftover is harmless (never read, truncated next time)
    return ec;
  }
  return SyncDirectory(dir);
}

std::error_code RemoveFile(const std::filesystem::path& path) {
  return ::unlink(path.c_str()) == 0 ? std::error_code{} : LastError();
}

std::error_code RemoveFileDurably(const std::filesystem::path& path) {
  if (auto ec = RemoveFile(path)) return ec == std::errc::no_such_file_or_directory ? std::error_code{} : ec;
  return SyncDirectory(path.parent_path());
}

std::error_code ReadWholeFile(const std::filesystem::path& path, std::size_t max_size,
                              std::vector<std::uint8_t>& out) {
  out.clear();
  Fd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) return LastError();
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) return LastError();
  if (!S_ISREG(st.st_mode)) return std::make_error_code(std::errc::invalid_argument);
  if (static_cast<std::uint64_t>(st.st_size) > max_size)
    return std::make_error_code(std::errc::file_too_large);
  out.resize(static_cast<std::size_t>(st.st_size));
  std::size_t got = 0;
  while (got < out.size()) {
    ssize_t n = ::read(fd.get(), out.data() + got, out.size() - got);
    if (n < 0) {
      if (errno == EINTR) continue;
      return LastError();
    }
    if (n == 0) break;  // the file shrank meanwhile: what was read is what there is
    got += static_cast<std::size_t>(n);
  }
  out.resize(got);
  return {};
}

}  // namespace canfleet::canopen
