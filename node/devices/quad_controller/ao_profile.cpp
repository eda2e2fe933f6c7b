#include "node/devices/quad_controller/ao_profile.hpp"

#include <array>
#include <cmath>
#include <span>

namespace canfleet::devices::quad {

namespace {

struct Point {
  int x;
  int y;
};

// Piecewise-linear through points of increasing x, flat beyond both ends. Two points with the
// same x make a step: the later point wins from that x on.
int Interpolate(int x, std::span<const Point> points) {
  if (x < points.front().x) return points.front().y;
  for (std::size_t i = 1; i < points.size(); ++i) {
    const Point& a = points[i - 1];
    const Point& b = points[i];
    if (x > b.x) continue;
    if (b.x == a.x) return b.y;
    const double t = static_cast<double>(x - a.x) / static_cast<double>(b.x - a.x);
    return static_cast<int>(std::lround(a.y + t * (b.y - a.y)));
  }
  return points.back().y;
}

}  // namespace

int ProfileCurrent(std::uint8_t response, int input, const ProfileInputs& in, const ProfileCurrents& out) {
  switch (response) {
    case 0: {
      const std::array<Point, 2> p{{{in.minimum, out.minimum}, {in.maximum, out.maximum}}};
      return Interpolate(input, p);
    }
    case 1: {
      const std::array<Point, 3> p{
          {{in.minimum, out.minimum}, {in.breakpoint_minimum, out.breakpoint}, {in.maximum, out.maximum}}};
      return Interpolate(input, p);
    }
    case 2: {
      if (input < in.deadband_maximum) return 0;
      const std::array<Point, 2> p{{{in.deadband_maximum, out.minimum}, {in.maximum, out.maximum}}};
      return Interpolate(input, p);
    }
    case 3: {
      if (input < in.deadband_maximum) return 0;
      const std::array<Point, 3> p{{{in.deadband_maximum, out.minimum},
                                    {in.breakpoint_maximum, out.breakpoint},
                                    {in.maximum, out.maximum}}};
      return Interpolate(input, p);
    }
    case 4: {
      if (input > in.deadband_minimum) return 0;
      const std::array<Point, 2> p{{{in.minimum, out.maximum}, {in.deadband_minimum, out.minimum}}};
      return Interpolate(input, p);
    }
    case 5: {
      if (input > in.deadband_minimum) return 0;
      const std::array<Point, 3> p{{{in.minimum, out.maximum},
                                    {in.breakpoint_minimum, out.breakpoint},
                                    {in.deadband_minimum, out.minimum}}};
      return Interpolate(input, p);
    }
    default:
      return 0;
  }
}

}  // namespace canfleet::devices::quad
