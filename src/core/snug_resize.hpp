#pragma once
// Resizing arrays that are rebuilt at about the same size again and again (neighbour lists, pair
// factors, particle fields with ghosts appended): when one must grow, it grows by 1/16 beyond what
// is needed instead of doubling (libstdc++'s growth), which had left half of the interaction lists
// and pair factors unused (measured: capacity exactly 2x the entries after the second evaluation).
#include <cstddef>
#include <vector>

namespace sphdisk {

template <class T>
void resize_snug(std::vector<T>& v, std::size_t n) {
  if (n > v.capacity()) v.reserve(n + n / 16);
  v.resize(n);
}

}  // namespace sphdisk
