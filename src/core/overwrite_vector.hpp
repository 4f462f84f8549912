#pragma once
// std::vector for buffers whose every element is written before it is read (list entries, pair
// factors, per-particle scratch): resize leaves the new elements of trivial types uninitialised
// instead of zero-filling them. The zero-fill is a serial memset on the thread that resizes, while
// the other threads wait; a block timestep's many partial evaluations, whose lists change size
// every time, would pay it again and again (docs/performance.md, "Serial passes and threads").
// Types with default member initialisers (Vec, Mat) are still initialised by them.
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/large_allocations.hpp"

namespace sphdisk {

// kLeaveUnset: for types with default member initialisers that are still plain data (Mat, Vec and
// structs of them: trivially copyable and destructible, so the allocation itself holds their
// objects, C++20 implicit object creation), resize constructs nothing at all, not even those
// initialisers. For per-particle sums that a parallel loop zeroes anyway: without stored lists the
// gradient sums are freed after every evaluation, and a serial zero-fill of each fresh buffer (with
// its page faults) would hold up the main thread (docs/performance.md, "Serial passes and threads").
template <class T, bool kLeaveUnset = false>
struct DefaultInitAllocator : std::allocator<T> {
  static_assert(!kLeaveUnset || (std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>),
                "kLeaveUnset leaves objects unconstructed: plain data only");
  using value_type = T;
  DefaultInitAllocator() noexcept = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U, kLeaveUnset>&) noexcept {}
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U, kLeaveUnset>;
  };
  // Buffers of a few MiB and more lie on transparent huge pages (core/large_allocations.hpp).
  T* allocate(std::size_t n) {
    if (on_huge_pages(n * sizeof(T))) return static_cast<T*>(map_huge_pages(n * sizeof(T)));
    return std::allocator<T>::allocate(n);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (on_huge_pages(n * sizeof(T))) return unmap_huge_pages(p, n * sizeof(T));
    std::allocator<T>::deallocate(p, n);
  }
  // Default-initialisation (or none) where std::allocator value-initialises (zeroes) ...
  template <class U>
  void construct(U* p) noexcept(kLeaveUnset || std::is_nothrow_default_constructible_v<U>) {
    if constexpr (!kLeaveUnset) ::new (static_cast<void*>(p)) U;
  }
  // ... and what std::allocator does for everything else.
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <class T, class U, bool kLeaveUnset>
bool operator==(const DefaultInitAllocator<T, kLeaveUnset>&, const DefaultInitAllocator<U, kLeaveUnset>&) noexcept {
  return true;
}

template <class T>
using OverwriteVector = std::vector<T, DefaultInitAllocator<T>>;

// Entries hold whatever the memory held until written (a new buffer's: anything).
template <class T>
using UnsetVector = std::vector<T, DefaultInitAllocator<T, true>>;

}  // namespace sphdisk
