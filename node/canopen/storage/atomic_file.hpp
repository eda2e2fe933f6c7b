#pragma once
/// @file Durable file I/O for stored parameters. A power cut or a killed process at any moment
/// leaves either the old file or the new one, never a mix: the new content goes to a temporary
/// file in the same directory, is fsync'ed, renamed over the old file (rename is atomic within a
/// file system, POSIX rename(2)), and the directory is fsync'ed so the rename itself is durable.
/// A crash before the rename leaves a stale "<name>.tmp" that readers never look at and the next
/// write truncates.
///
/// Synchronous on purpose: a node is single-threaded and its files are a few KB, so a store
/// costs about one fsync of latency on the node's event loop; the SDO reply follows once the file is durable.

#include <cstdint>
#include <filesystem>
#include <span>
#include <system_error>
#include <vector>

namespace canfleet::canopen {

/// The temporary file WriteFileAtomically uses for `path`.
std::filesystem::path TempPathFor(const std::filesystem::path& path);

/// Replaces `path` by `bytes` atomically and durably; creates missing parent directories.
/// Returns the first error (errno as std::generic_category) or an empty code.
std::error_code WriteFileAtomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);

/// Removes `path` (a missing file is success) and fsyncs its directory.
std::error_code RemoveFileDurably(const std::filesystem::path& path);

/// Reads a whole regular file of at most `max_size` bytes. A missing file gives
/// std::errc::no_such_file_or_directory, a larger one std::errc::file_too_large.
std::error_code ReadWholeFile(const std::filesystem::path& path, std::size_t max_size,
                              std::vector<std::uint8_t>& out);

}  // namespace canfleet::canopen
