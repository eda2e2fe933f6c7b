#pragma once
/// @file Giving the heap that start-up freed back to the system (idle RSS, issues 16-18).

namespace canfleet::node {

/// Returns the free memory at the top of the heap and every whole free page inside it to the
/// kernel (glibc malloc_trim). Start-up frees far more than an idle node ever allocates again (the
/// EDS text, its parsed sections, the intermediate copies of the dictionary), and glibc keeps freed
/// memory mapped unless asked: without this, a valve controller stays ~0.5 MB above its idle need.
/// Called once the node is built and once it is powered on; it costs one walk over the heap.
void ReleaseFreedHeap();

/// One malloc arena for every thread (glibc M_ARENA_MAX = 1), set before any thread starts. The
/// node's event loop does almost all the allocating; DDS's and the telemetry's threads would each
/// get an arena of their own (a 64 MB reservation whose touched pages, headers and free lists count
/// in the RSS and are never given back by malloc_trim of the main arena). Contention is nil: the
/// other threads allocate a few times a second. Also no padding on top of the heap and a low trim
/// threshold: glibc's defaults (128 KiB pad, a threshold that grows to 32 MiB) keep freed memory
/// mapped that an idle node never needs again (0.2 MiB of the data logger's idle RSS).
void UseOneMallocArena();

}  // namespace canfleet::node
