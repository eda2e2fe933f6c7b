#include "node/process/release_memory.hpp"

#include <malloc.h>

namespace canfleet::node {

void ReleaseFreedHeap() {
  malloc_trim(0);
}

void UseOneMallocArena() {
  mallopt(M_ARENA_MAX, 1);
  mallopt(M_TOP_PAD, 0);
  mallopt(M_TRIM_THRESHOLD, 64 * 1024);
}

}  // namespace canfleet::node
