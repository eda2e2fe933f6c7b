#pragma once
/// @file Claiming a Unix-domain socket path for listening.

#include <string>

namespace canfleet::transport {

/// Makes `path` free for bind(): a stale socket file (left by a broker that was killed: connect
/// is refused) is removed; a live one (someone accepts connections) or a file that is not a
/// socket is an error. Throws std::runtime_error saying which.
void ClaimUnixSocketPath(const std::string& path);

}  // namespace canfleet::transport
