#pragma once
/// @file The objects an input's type rewrites (AX023241 1.2.1: "By changing [6110h], and associated
/// with its object 2100h AI Input Range, other objects will be automatically updated by the
/// controller. The list of affected objects include Input Scaling FV & PV objects (7120h, 7121h,
/// 7122h & 7123h) and also Span Start and End objects (7148h and 7149h)"). The manual gives no
/// values; these are the emulator's (README.md, "Input types"), in field-value units:
///
/// | input (6110h / 6112h, 2100h)       | 2102h | 7148h  | 7120h=7121h | 7122h=7123h | 7149h | 2111h |
/// |---|---|---|---|---|---|---|
/// | frequency 0.5-50 Hz (60, 0)        | 2 | 40     | 50 | 5000  | 5250  | 50  |
/// | frequency 10 Hz-1 kHz (60, 1)      | 1 | 80     | 100 | 10000 | 10500 | 100 |
/// | frequency 100 Hz-10 kHz (60, 2)    | 0 | 80     | 100 | 10000 | 10500 | 100 |
/// | PWM (10000, 0 or 1), 0.1 %         | 1 | 10     | 50 | 950   | 990   | 1   |
/// | digital (6112h = 10)               | 0 | 0      | 0 | 1     | 1     | 0   |
/// | quadrature count (10002, 0)        | 0 | -32768 | 0 | 10000 | 32767 | 100 |
/// | quadrature direction (10002, 1)    | 0 | 0      | 0 | 1     | 1     | 0   |
/// | quadrature speed, rpm (10002, 2)   | 0 | 0      | 0 | 3000  | 32767 | 100 |
///
/// The PWM and digital rows are the family's (valve UMAX020411A Table 10); 2102h and 2111h are
/// rewritten too ("include": the list is not closed), so the range's top fits the INTEGER16 field
/// value. The printed factory values (2102h 3, 7120h-7123h 0, 7148h/7149h 200/4800) stay what a
/// factory-new or restored device holds until 6110h or 2100h is written.

#include <cstdint>
#include <optional>

namespace canfleet::devices::encoder {

struct InputDefaults {
  std::uint8_t fv_digits;   ///< 2102h
  std::int16_t span_start;  ///< 7148h
  std::int16_t scaling1;    ///< 7120h and 7121h
  std::int16_t scaling2;    ///< 7122h and 7123h
  std::int16_t span_end;    ///< 7149h
  std::int16_t hysteresis;  ///< 2111h
};

/// The row for 6110h `sensor_type`, 6112h `mode` and 2100h `range`; nullopt for a channel that is
/// off or a combination Table 3 greys out.
std::optional<InputDefaults> InputDefaultsFor(std::uint16_t sensor_type, std::uint8_t mode,
                                              std::uint8_t range);

/// The largest 2100h value Table 3 allows for the type (PWM 1, the others 2).
std::uint8_t MaxRange(std::uint16_t sensor_type, std::uint8_t mode);

}  // namespace canfleet::devices::encoder
