#pragma once
/// @file Counts global operator new calls, so a test can prove a hot path does not allocate.
/// Link the `canfleet_test_alloc` object library: it replaces the global operator new/delete for
/// the whole test binary. Kept in its own translation unit so the compiler never inlines the
/// replaced operators into test code (GCC then warns about malloc/free pairs at -O2).

#include <cstdint>

namespace canfleet::test {

/// Global operator new calls so far in this process, from every thread.
std::uint64_t AllocationCount();

}  // namespace canfleet::test
