#pragma once
// Large arrays given back to the system when freed (glibc). By default glibc's threshold for
// mapping an allocation on its own rises to the largest array freed so far, after which arrays of
// that size come from its heap, whose freed pages mostly stay with the process: with scratch that
// is freed and allocated again at changing sizes (the pair loops without stored lists, whose point
// is to fit), the peak memory would creep up cycle after cycle (docs/performance.md,
// "Memory per particle").
#include <cstddef>
#include <cstdint>
#include <new>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#if defined(__linux__)
#include <sys/mman.h>
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

// Scratch buffers rebuilt every evaluation (the gradient sums, lists and pair factors of pairs
// searched anew) are mapped afresh each time; on 4 KiB pages a buffer of tens of MiB costs thousands
// of page faults per evaluation. Those of kHugePageScratch bytes and more are mapped on 2 MiB
// boundaries with transparent huge pages asked for (Linux, madvise), 512x fewer faults; their
// size is rounded up to whole huge pages. Elsewhere they come from operator new.
inline constexpr std::size_t kHugePage = std::size_t{2} << 20;
inline constexpr std::size_t kHugePageScratch = 2 * kHugePage;

constexpr bool on_huge_pages(std::size_t bytes) {
#if defined(__linux__)
  return bytes >= kHugePageScratch;
#else
  (void)bytes;
  return false;
#endif
}

constexpr std::size_t whole_huge_pages(std::size_t bytes) { return (bytes + kHugePage - 1) / kHugePage * kHugePage; }

// A mapping of whole huge pages for `bytes` (on_huge_pages(bytes) must hold), aligned to a huge
// page: mapped one huge page larger, the slack on either side unmapped.
inline void* map_huge_pages(std::size_t bytes) {
#if defined(__linux__)
  const std::size_t length = whole_huge_pages(bytes);
  void* raw = mmap(nullptr, length + kHugePage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const auto start = reinterpret_cast<std::uintptr_t>(raw);
  const std::uintptr_t aligned = (start + kHugePage - 1) / kHugePage * kHugePage;
  if (aligned > start) munmap(raw, aligned - start);
  if (const std::size_t tail = start + kHugePage - aligned; tail > 0) munmap(reinterpret_cast<void*>(aligned + length), tail);
  madvise(reinterpret_cast<void*>(aligned), length, MADV_HUGEPAGE);
  return reinterpret_cast<void*>(aligned);
#else
  (void)bytes;
  throw std::bad_alloc();
#endif
}

inline void unmap_huge_pages(void* p, std::size_t bytes) noexcept {
#if defined(__linux__)
  munmap(p, whole_huge_pages(bytes));
#else
  (void)p, (void)bytes;
#endif
}

}  // namespace sphdisk
