#pragma once
// Resizing arrays that are rebuilt at about the same size again and again (neighbour lists, pair
// factors, particle fields with ghosts appended): when one must grow, it grows by 1/16 beyond what
// is needed instead of doubling (libstdc++'s growth), which can leave half of the interaction lists'
// and pair factors' capacity unused from the second evaluation on.
#include <cstddef>
#include <vector>

namespace sphdisk {

template <class T, class A>
void resize_snug(std::vector<T, A>& v, std::size_t n) {
  if (n > v.capacity()) v.reserve(n + n / 16);
  v.resize(n);
}

// resize_snug for arrays of which every entry is written before it is read (scratch, rebuilt
// lists): when it must grow, the old buffer is freed before the new one is allocated, so the two
// are never held at once (a copy of the old entries at the peak of a run's memory) and nothing is
// copied.
template <class T, class A>
void renew_snug(std::vector<T, A>& v, std::size_t n) {
  if (n > v.capacity()) {
    v = std::vector<T, A>();
    v.reserve(n + n / 16);
  }
  v.resize(n);
}

// Frees the memory of each argument (a vector, or a struct of them), leaving it empty.
template <class... T>
void release_memory(T&... v) {
  ((v = T{}), ...);
}

// renew_snug that never shrinks, for per-particle scratch of which each evaluation uses a prefix
// of changing length (the entries past it are stale, all of them after a growth): after a shrink,
// every growth zero-filled the new entries on one thread while the others waited (block
// timesteps' partial evaluations).
template <class T, class A>
void grow_snug(std::vector<T, A>& v, std::size_t n) {
  if (v.size() < n) renew_snug(v, n);
}

// A per-thread scratch buffer of at least n entries for one list's values: it only ever grows, so
// that the many lists of an evaluation (sizes varying by tens around their mean) neither zero-fill
// the entries a resize adds nor pay for a size update. The values beyond n are stale.
template <class T, class A>
T* scratch_for(std::vector<T, A>& v, std::size_t n) {
  if (v.size() < n) v.resize(n + n / 4);
  return v.data();
}

}  // namespace sphdisk
