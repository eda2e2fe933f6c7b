#pragma once
/// @file The six output current profiles of an input-controlled proportional output (AX020506
/// §2.6 graphs, 3020h §3.5.2; input points 2020h-2070h §3.3.2-7, currents 3030h-3050h §3.5.3-5).
///
///   0 single profile, single slope:  (2020h, 3030h) → (2070h, 3050h)
///   1 single profile, dual slope:    (2020h, 3030h) → (2030h, 3040h) → (2070h, 3050h)
///   2 dual profile A, single slope:  (2050h, 3030h) → (2070h, 3050h)
///   3 dual profile A, dual slope:    (2050h, 3030h) → (2060h, 3040h) → (2070h, 3050h)
///   4 dual profile B, single slope:  (2040h, 3030h) → (2020h, 3050h), the current rising as the
///                                    input falls
///   5 dual profile B, dual slope:    (2040h, 3030h) → (2030h, 3040h) → (2020h, 3050h)
/// Beyond the last point of its active side a profile holds its end current (the graphs' "no error
/// checking" lines; with error checking the region past 2010h/2080h is the error mode, handled by
/// the fault state). A dual profile is off (0 mA) on the other side of its deadband edge: A below
/// 2050h, B above 2040h (the two halves of a joystick driving the A and B coils of one valve).

#include <cstdint>

namespace canfleet::devices::quad {

/// 2020h..2070h of the controlling input, in its field value units.
struct ProfileInputs {
  int minimum = 0;             ///< 2020h
  int breakpoint_minimum = 0;  ///< 2030h
  int deadband_minimum = 0;    ///< 2040h
  int deadband_maximum = 0;    ///< 2050h
  int breakpoint_maximum = 0;  ///< 2060h
  int maximum = 0;             ///< 2070h
};

/// 3030h..3050h of the output, mA.
struct ProfileCurrents {
  int minimum = 0;
  int breakpoint = 0;
  int maximum = 0;
};

/// The output current in mA for input field value `input` under 3020h response `response`
/// (0-5; others give 0).
int ProfileCurrent(std::uint8_t response, int input, const ProfileInputs& in, const ProfileCurrents& out);

}  // namespace canfleet::devices::quad
