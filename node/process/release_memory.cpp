#include "node/process/release_memory.hpp"

#include <malloc.h>

namespace canfleet::node {

void ReleaseFreedHeap() {
  malloc_trim(0);
}

}  // namespace canfleet::node
