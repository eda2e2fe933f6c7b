#include "orchestrator/capture/capture_tap.hpp"

namespace canfleet::capture {

void CaptureTap::Deliver(std::span<const broker::TimedFrame> frames) {
  for (const auto& f : frames)
    writer_.Write(f.frame, origin_ + f.time);
  frames_ += frames.size();
}

}  // namespace canfleet::capture
