#pragma once
/// @file The interface of a capture format: frames with their wall-clock time go in, a file
/// comes out.

#include <chrono>
#include <string>

#include "bus/can_frame.hpp"
#include "clock/wall_clock.hpp"

namespace canfleet::capture {

/// Wall-clock time (Unix epoch), as capture files expect it (clock/wall_clock.hpp).
using canfleet::WallTime;

/// One capture file being written. Writes are buffered; Flush pushes them to the file, Close
/// flushes and closes (the destructor closes too). A failed write (disk full...) is not thrown:
/// the writer stops writing, `ok()` turns false and `error()` says why, so a capture can never
/// take down the bus it watches.
class CaptureWriter {
 public:
  virtual ~CaptureWriter() = default;
  /// Appends one frame seen at `time`. Ignored after Close or a failure.
  virtual void Write(const CanFrame& frame, WallTime time) = 0;
  virtual void Flush() = 0;
  virtual void Close() = 0;
  virtual bool ok() const = 0;
  virtual const std::string& error() const = 0;
};

}  // namespace canfleet::capture
