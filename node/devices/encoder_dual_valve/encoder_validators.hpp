#pragma once
/// @file The AX023241's SDO write rules beyond the table's limits, and the writes that rewrite
/// other objects (README.md "Write rules"):
/// - 6110h only 60, 10000, 10002 (Table 1: "no values other than what are shown here will be
///   accepted"); 6112h only 0, 1, 10 (C3-1.3.5); 6310h only 0, 10, 20, 40, 1000, 1020 (Table 8);
///   2100h within Table 3's column of the input's type (PWM: 0-1), else 06090031h.
/// - 6110h written: 2100h back to 0 ("AI Range will automatically be updated with this value"),
///   then 6110h/2100h/6112h written: 2102h, 7120h-7123h, 7148h/7149h, 2111h from
///   input_defaults.hpp, and the quadrature step counter restarts (quadrature.hpp).
/// - 6310h written: the type's FV decimals and limits (6332h/6302h, 7320h-7323h), fault value 7341h
///   and override value 2300h (1.4: "Changing this object causes other output type related objects
///   match the selected type").
/// - every (source, number) pair (2340h/2341h, 2350h/2351h, 2360h/2361h, 30x0h/30x1h, 4x00h/4x01h,
///   2453h/2454h, 2455h/2456h): a number outside its source's range (encoder_sources.hpp) is
///   refused with 06090031h/06090032h, a source that makes the stored number invalid with
///   06040043h (write the number first).
/// - 2457h = 1 (setpoint control) sets 2453h to 9 (control constant) and 2453h then refuses any
///   other value with 08000022h (1.8: "automatically gets updated ... and cannot be changed").
/// - 3413h >= 1 (pulses per revolution), 4x40h -100..100 (gain -1.0..1.0), 5010h sub 1/2 keep
///   FALSE 0.0 / TRUE 1.0 (1.5 "fixed") : 06090032h/06090031h/06090030h.

#include <functional>

#include "node/canopen/stack/canopen_stack.hpp"
#include "node/devices/blocks/control_source.hpp"

namespace canfleet::devices::encoder {

/// `on_input_reconfigured(ch)` runs after 6110h/2100h/6112h of input ch (0-based) was written.
void InstallEncoderValidators(canopen::CanopenStack& stack, const blocks::ControlSources& sources,
                              std::function<void(int ch)> on_input_reconfigured);

/// The dependent objects of input `ch` for its current type (no-op for a channel that is off).
void ApplyInputDefaults(canopen::ObjectDictionary& od, int ch);
/// The dependent objects of output `n` for its current type.
void ApplyOutputDefaults(canopen::ObjectDictionary& od, int n);

}  // namespace canfleet::devices::encoder
