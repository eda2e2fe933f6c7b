#pragma once
/// @file The power supply's write checks beyond the limits its dictionary table carries. A refused
/// SDO write answers an abort and keeps the previous value.
/// - 1029h sub 1-4 (§2.2.13): "Object 1029h Error Behaviour can ONLY be changed if there are NO
///   errors present": refused with 08000022h while 1001h is not 0 (README.md, choice 14).
/// - Enumerations with gaps (§2.3.1, §2.3.16; 06090030h): 6010h.1 FCh/FDh/FFh, 6010h.2 FCh/FFh,
///   6010h.4 FCh/FDh/FFh, 6200h.2 FCh/FDh/FFh, 6200h.3 FCh/FFh, 6200h.5 FCh/FDh/FFh.
/// - 2520h.n < 2522h.n (§2.4.13 "must always be smaller than 2522h", §2.4.14 "must always be
///   larger"): 06090031h / 06090032h.
/// - 5B50h a CiA 305 bit-timing index 0-8 other than the reserved 5 (06090030h); 5B51h a node-ID
///   1-127 (06090032h / 06090031h). The manual gives these objects no further behaviour.

#include "node/canopen/stack/canopen_stack.hpp"

namespace canfleet::devices::ps {

/// Installs the checks on `stack`'s dictionary; `stack` must outlive its dictionary's use.
void InstallPsValidators(canopen::CanopenStack& stack);

}  // namespace canfleet::devices::ps
