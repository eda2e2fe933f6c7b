#pragma once
/// @file The Quad's write checks beyond the limits its EDS carries (AX020506 §3). A refused write
/// answers an SDO abort and keeps the previous value:
/// - enumerations: 6110h (AIN 40/42/51/52, FIN 60/10000), 6112h (0/1/10/20), 3001h (0-6, 11-16),
///   3010h (0-6), 3020h (0-5), 30A0h (0-2), 6310h (20/1000) → 06090030h (§3.3.13, §3.3.14,
///   §3.4.1, §3.5.1, §3.5.2, §3.5.10, §3.5.15: "SDO abort download error, and the previous value
///   will remain unchanged");
/// - ranges relative to other objects (the "Value Range" rows of §3.2.2-3, §3.3.1-8): 2001h ≤
///   2002h ≤ full scale; 2010h ≤ 2020h ≤ ... ≤ 2080h ≤ full scale, where full scale is 5000,
///   10000 or 20000 by the AIN's 6110h and 10000 for FIN → 06090031h above, 06090032h below;
/// - output control in pre-operational: SDO writes to 6200h, 7330h, 7F50h and 6F52h → 08000022h
///   (§4.2: "the controller will not allow any SDO writes to control the outputs");
/// - 7330h while 6F52h validates a received PV → 08000022h (§3.5.20).

#include "node/canopen/stack/canopen_stack.hpp"

namespace canfleet::devices::quad {

/// Installs the checks on `stack`'s dictionary; `stack` must outlive its dictionary's use.
void InstallQuadValidators(canopen::CanopenStack& stack);

/// Full scale of input `ch`'s field value (0-based channel) for its current sensor type.
int InputFullScale(const canopen::ObjectDictionary& od, int ch);

}  // namespace canfleet::devices::quad
