#include "node/devices/blocks/span_monitor.hpp"

namespace canfleet::devices::blocks {

void SpanMonitor::Update(const SpanParams& params, double fv, std::chrono::milliseconds elapsed) {
  if (!params.enabled) {
    Reset();
    return;
  }
  if (flag_ != SpanFlag::kNone) held_ += elapsed;

  SpanFlag next = flag_;
  if (fv < params.span_start) {
    next = SpanFlag::kLow;
  } else if (fv > params.span_end) {
    next = SpanFlag::kHigh;
  } else if (flag_ == SpanFlag::kLow && fv >= params.span_start + params.hysteresis) {
    next = SpanFlag::kNone;
  } else if (flag_ == SpanFlag::kHigh && fv <= params.span_end - params.hysteresis) {
    next = SpanFlag::kNone;
  }
  if (next != flag_) {
    flag_ = next;
    faulted_ = false;
    held_ = std::chrono::milliseconds{0};
  }
  if (flag_ != SpanFlag::kNone && held_ >= params.delay) faulted_ = true;
}

void SpanMonitor::Reset() {
  flag_ = SpanFlag::kNone;
  faulted_ = false;
  held_ = std::chrono::milliseconds{0};
}

}  // namespace canfleet::devices::blocks
