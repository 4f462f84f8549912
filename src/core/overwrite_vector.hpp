#pragma once
// std::vector for buffers whose every element is written before it is read (list entries, pair
// factors, per-particle scratch): resize leaves the new elements of trivial types uninitialised
// instead of zero-filling them. The zero-fill is a serial memset on the thread that resizes; in
// a block timestep's many partial evaluations, whose lists change size every time, such fills were
// a few percent of the run's time on the main thread while the other threads waited (perf of a
// 100k ring run on two threads, docs/performance.md). Types with default member initialisers
// (Vec, Mat) are still initialised by them.
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

namespace sphdisk {

template <class T>
struct DefaultInitAllocator : std::allocator<T> {
  using value_type = T;
  DefaultInitAllocator() noexcept = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  // Default-initialisation where std::allocator value-initialises (zeroes) ...
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  // ... and what std::allocator does for everything else.
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <class T, class U>
bool operator==(const DefaultInitAllocator<T>&, const DefaultInitAllocator<U>&) noexcept {
  return true;
}

template <class T>
using OverwriteVector = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace sphdisk
