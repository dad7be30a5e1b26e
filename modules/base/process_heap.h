#pragma once
// The heap of a short-lived process that allocates a few to a few hundred megabytes and frees little of it
// before it exits (a `calibrate`: the observations, the Jacobians, the report).
//
// On a virtual machine the first touch of a 4 KiB page costs 10-20 us of kernel time (measured on the
// project's build machine: 10 MiB touched page by page, 0.038 s CPU), so a 25-pose calibration spent a
// fifth of its CPU time in page faults. PrepareProcessHeap asks glibc's malloc to take memory from the
// operating system in large steps and to keep what is freed (no trimming, no mmap per large block), and
// asks the kernel for transparent huge pages on that memory where it allows them (madvise: a no-op when
// THP is "never", and 2 MiB per fault instead of 4 KiB otherwise). Nothing about the results changes:
// only where the bytes live.
#include <cstddef>

namespace selfcal {

struct HeapPreparation {
  bool malloc_options_set = false;  // mallopt accepted the thresholds
  std::size_t huge_page_bytes = 0;  // bytes of the heap advised to use transparent huge pages
};

// Call once at the start of main, before other threads exist. `reserve_bytes` is the first step by which
// the heap grows (and by which it grows after); it is address space, not memory, until touched.
HeapPreparation PrepareProcessHeap(std::size_t reserve_bytes = std::size_t{32} << 20);

}  // namespace selfcal
