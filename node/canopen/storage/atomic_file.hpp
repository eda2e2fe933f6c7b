#pragma once
/// @file Durable file I/O for stored parameters. A power cut or a killed process at any moment
/// leaves either the old file or the new one, never a mix: the new content goes to a temporary
/// file in the same directory, is fsync'ed, renamed over the old file (rename is atomic within a
/// file system, POSIX rename(2)), and the directory is fsync'ed so the rename itself is durable.
/// A crash before the rename leaves a stale "<name>.tmp" that readers never look at and the next
/// write truncates.
///
/// That guarantee is per file. A change of several files at once (1010h/1011h sub 1: all three
/// parameter groups) needs more: store_transaction.hpp builds it from the pieces below (a staged
/// file written durably in place, a rename, a directory fsync), so that after a kill at any moment
/// every group comes from the same save.
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

/// Writes `bytes` to `path` in place (created or truncated) and fsyncs the file, not its directory.
/// Not atomic: a crash part-way leaves a partial file, so only files that no reader trusts until
/// something else says so (a temporary or staged file) are written this way.
std::error_code WriteFileDurably(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);

/// rename(2): atomically replaces `to` by `from` (same file system). Not durable until the
/// directory is synced.
std::error_code RenameFile(const std::filesystem::path& from, const std::filesystem::path& to);

/// fsyncs the directory `dir` ("" = the current one), making the renames, creations and removals
/// of entries in it durable.
std::error_code SyncDirectory(const std::filesystem::path& dir);

/// Replaces `path` by `bytes` atomically and durably; creates missing parent directories.
/// Returns the first error (errno as std::generic_category) or an empty code.
std::error_code WriteFileAtomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);

/// unlink(2) without a directory fsync; a missing file gives std::errc::no_such_file_or_directory
/// (callers that only want it gone treat that as success).
std::error_code RemoveFile(const std::filesystem::path& path);

/// Removes `path` (a missing file is success) and fsyncs its directory.
std::error_code RemoveFileDurably(const std::filesystem::path& path);

/// Reads a whole regular file of at most `max_size` bytes. A missing file gives
/// std::errc::no_such_file_or_directory, a larger one std::errc::file_too_large.
std::error_code ReadWholeFile(const std::filesystem::path& path, std::size_t max_size,
                              std::vector<std::uint8_t>& out);

}  // namespace canfleet::canopen
