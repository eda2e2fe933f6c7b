#pragma once
/// @file Giving the heap that start-up freed back to the system (idle RSS, issues 16-18).

namespace canfleet::node {

/// Returns the free memory at the top of the heap and every whole free page inside it to the
/// kernel (glibc malloc_trim). Start-up frees far more than an idle node ever allocates again (the
/// EDS text, its parsed sections, the intermediate copies of the dictionary), and glibc keeps freed
/// memory mapped unless asked: without this, a valve controller stays ~0.5 MB above its idle need.
/// Called once the node is built and once it is powered on; it costs one walk over the heap.
void ReleaseFreedHeap();

}  // namespace canfleet::node
