#pragma once
/// @file Helpers for the capture tests: fixed wall-clock times, temporary files, reading a file
/// back.

#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "bus/capture/capture_writer.hpp"

namespace canfleet::capture::test {

/// 2023-11-14 22:13:20 UTC plus `us` microseconds.
inline WallTime At(std::int64_t seconds, std::int64_t us = 0) {
  return WallTime(std::chrono::seconds(seconds) + std::chrono::microseconds(us));
}

/// A path in a fresh directory removed with the object.
class TempPath {
 public:
  explicit TempPath(const std::string& name) {
    dir_ = std::filesystem::temp_directory_path() /
           ("canfleet-capture-" + std::to_string(::getpid()) + "-" + std::to_string(counter_++));
    std::filesystem::create_directories(dir_);
    path_ = dir_ / name;
  }
  ~TempPath() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  static inline int counter_ = 0;
  std::filesystem::path dir_;
  std::filesystem::path path_;
};

inline std::vector<std::uint8_t> ReadBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace canfleet::capture::test
