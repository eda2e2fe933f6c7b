#include "orchestrator/fleet/capture_path.hpp"

#include <algorithm>
#include <stdexcept>

namespace canfleet::fleet {

namespace fs = std::filesystem;

namespace {

/// `path` is `folder` or inside it (both canonical).
bool Inside(const fs::path& path, const fs::path& folder) {
  return std::mismatch(folder.begin(), folder.end(), path.begin(), path.end()).first == folder.end();
}

std::string List(const std::vector<fs::path>& folders) {
  std::string out;
  for (const auto& f : folders)
    out += (out.empty() ? "" : ", ") + f.string();
  return out;
}

}  // namespace

CaptureFolders CaptureFoldersAt(const fs::path& dir, const fs::path& state_root) {
  const auto base = fs::absolute(dir).lexically_normal();
  return {base, {base, fs::absolute(state_root).lexically_normal()}};
}

fs::path ResolveCapturePath(const std::string& requested, const CaptureFolders& folders) {
  if (requested.empty()) throw std::invalid_argument("capture needs a file (--file)");
  const fs::path given(requested);
  const fs::path path = (given.is_absolute() ? given : folders.base / given).lexically_normal();
  const auto name = path.filename();
  if (name.empty() || name == "." || name == "..")
    throw std::invalid_argument("capture file " + requested + ": names a folder, not a file");
  // Symbolic links in the existing part of the path are followed: a link inside the state folder
  // that points elsewhere does not lead out of it.
  const fs::path real = fs::weakly_canonical(path);
  const bool allowed = std::any_of(
      folders.allowed.begin(), folders.allowed.end(),
      [&](const fs::path& folder) { return Inside(real.parent_path(), fs::weakly_canonical(folder)); });
  if (!allowed)
    throw std::invalid_argument("capture file " + path.string() +
                                ": the orchestrator writes captures only inside " + List(folders.allowed) +
                                " (a relative --file goes to " + folders.base.string() +
                                "; canfleet up --capture-dir names another folder)");
  std::error_code ec;
  const bool exists = fs::symlink_status(real, ec).type() != fs::file_type::not_found ||
                      fs::symlink_status(path, ec).type() != fs::file_type::not_found;
  if (exists)
    throw std::invalid_argument("capture file " + path.string() + " exists: a capture never replaces a file");
  fs::create_directories(real.parent_path(), ec);
  if (ec) throw std::invalid_argument("capture folder " + real.parent_path().string() + ": " + ec.message());
  return real;
}

}  // namespace canfleet::fleet
