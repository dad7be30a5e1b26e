#include "base/process_heap.h"

#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>

namespace selfcal {

HeapPreparation PrepareProcessHeap(std::size_t reserve_bytes) {
  HeapPreparation out;
  const int step = static_cast<int>(reserve_bytes);
  // Large blocks from the heap rather than one mmap each (which is unmapped on free, and faulted in again
  // on the next allocation of the same size); freed memory kept; the heap grown `reserve_bytes` at a time.
  out.malloc_options_set =
      mallopt(M_MMAP_THRESHOLD, step) == 1 && mallopt(M_TRIM_THRESHOLD, 2 * step) == 1 && mallopt(M_TOP_PAD, step) == 1;
  // A block larger than what is left at the heap's top grows the heap by the pad: advise the whole 2 MiB
  // pages from that block to the new end.
  void* first = std::malloc(std::size_t{1} << 20);
  if (first == nullptr) return out;
  const std::uintptr_t huge = std::uintptr_t{2} << 20;
  const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(first) + huge - 1) & ~(huge - 1);
  const std::uintptr_t end = reinterpret_cast<std::uintptr_t>(sbrk(0)) & ~(huge - 1);
  if (end > begin && madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE) == 0) {
    out.huge_page_bytes = end - begin;
  }
  std::free(first);
  return out;
}

}  // namespace selfcal
