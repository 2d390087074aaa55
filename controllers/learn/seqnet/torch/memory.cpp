#include "animrt/learn/seqnet/memory.hpp"

#include <malloc.h>

namespace animrt::seqnet {

void keep_freed_memory() {
  mallopt(M_MMAP_THRESHOLD, 256 * 1024 * 1024);
  mallopt(M_TRIM_THRESHOLD, 1024 * 1024 * 1024);
}

}  // namespace animrt::seqnet
