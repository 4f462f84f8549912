#pragma once
// Large arrays given back to the system when freed (glibc). By default glibc's threshold for
// mapping an allocation on its own rises to the largest array freed so far, after which arrays of
// that size come from its heap, whose freed pages mostly stay with the process: with scratch that
// is freed and allocated again at changing sizes (the pair loops without stored lists, whose point
// is to fit), the peak memory would creep up cycle after cycle (docs/performance.md,
// "Memory per particle").
#include <cstddef>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace sphdisk {

// Arrays of at least `bytes` are mapped on their own from now on and unmapped when freed. Smaller
// ones come from the heap, which keeps up to 32x that much free memory at its top: fixing the
// mapping threshold also fixes the trim threshold, at 128 KiB, and then each freed array of
// 128 KiB-1 MiB would go back to the system and come back as fresh pages, page faults that slow
// the block integrator's sorts and the reorders.
inline void map_large_allocations(std::size_t bytes) {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, static_cast<int>(bytes));
  mallopt(M_TRIM_THRESHOLD, static_cast<int>(32 * bytes));
#else
  (void)bytes;
#endif
}

}  // namespace sphdisk
