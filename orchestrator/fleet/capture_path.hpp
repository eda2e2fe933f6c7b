#pragma once
/// @file Where the control API may have the orchestrator write a capture (issue 32: "files only
/// where they belong"). A request names a file; the orchestrator writes it only inside the
/// fleet's own folders, never over an existing file, so that a client of the control API, which
/// may reach it from another host, cannot have it write or truncate anything else its user can.

#include <filesystem>
#include <string>
#include <vector>

namespace canfleet::fleet {

struct CaptureFolders {
  /// Where a relative path goes (`canfleet up --capture-dir`; default <state root>/captures).
  std::filesystem::path base;
  /// Folders an absolute path may name a file in (any depth): the base and the fleet's state root.
  std::vector<std::filesystem::path> allowed;
};

/// The folders of a fleet whose captures go to `dir` (absolute or relative to the working folder)
/// and may also go anywhere in its state root.
CaptureFolders CaptureFoldersAt(const std::filesystem::path& dir, const std::filesystem::path& state_root);

/// The absolute path to write `requested` to, its parent folders created. Throws
/// std::invalid_argument saying why when the path is empty, names a folder, resolves (symbolic
/// links followed) outside every allowed folder, or names a file that exists.
std::filesystem::path ResolveCapturePath(const std::string& requested, const CaptureFolders& folders);

}  // namespace canfleet::fleet
