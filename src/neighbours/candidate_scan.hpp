#pragma once
// The innermost loops of the 2D neighbour search: the candidates of a range of cell-grid slots that
// lie within a radius of a point, appended in slot order (neighbour_lists.cpp), the dropping of
// listed candidates beyond a smaller radius, and, for the half lists (pair_lists.cpp), where a
// gather list meets its own particle and which earlier partners lack it. In scalar code a candidate
// costs ~20 instructions (a store per candidate, the count advanced by the test: branch-free, not
// vectorisable); on CPUs with AVX-512 eight are tested at once and the accepted ones packed by
// compress instructions (~3 instructions per candidate). The CPU is asked at run time
// (core/vector_isa.hpp), so the default (portable) build uses them too. Both paths give the same
// results bit for bit: squared distances are formed by the same operations as norm2 (core/vec.hpp),
// with floating-point contraction off in this file, and the tests compare the two.
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "core/vec.hpp"
#include "neighbours/cell_grid.hpp"

namespace sphdisk {

// Room the scans may write past the entries they return (whole vectors of eight).
constexpr std::size_t kScanSlack = 8;

// What a scan accepts: |xs[s] - x|^2 < r2, index != self, index < limit.
template <int D>
struct ScanTarget {
  Vec<D> x;
  double r2;
  std::uint32_t self;   // UINT32_MAX: none
  std::uint32_t limit;  // UINT32_MAX: none
  // The slots that exist (js and xs hold at least this many): a vector scan may read past the end
  // of its range within them (whole vectors, the lanes beyond the range ignored) instead of masking
  // its loads, which is slow on AMD's AVX-512 CPUs. 0: only the range is read.
  std::uint32_t readable = 0;
};

// Appends the accepted candidates of slots [s0, s1) (indices js[s], positions xs[s]) to out, their
// squared distances to d2 (unless null), in slot order; returns how many. out and d2 need room for
// s1 - s0 + kScanSlack entries.
std::size_t scan_candidates(const std::uint32_t* js, const Vec<2>* xs, std::uint32_t s0, std::uint32_t s1,
                            const ScanTarget<2>& target, std::uint32_t* out, double* d2);
// The same in 3D (vectorised with AVX-512 only).
std::size_t scan_candidates(const std::uint32_t* js, const Vec<3>* xs, std::uint32_t s0, std::uint32_t s1,
                            const ScanTarget<3>& target, std::uint32_t* out, double* d2);

// The scalar scan, in any dimension (scan_candidates' fallback). Branch-free append:
// every candidate is written, the end advances only for accepted ones (about half the candidates
// are accepted at random, so a branch would mispredict often).
template <int D>
std::size_t scan_candidates_scalar(const std::uint32_t* js, const Vec<D>* xs, std::uint32_t s0, std::uint32_t s1,
                                   const ScanTarget<D>& t, std::uint32_t* out, double* d2) {
  std::size_t found = 0;
  for (std::uint32_t s = s0; s < s1; ++s) {
    const std::uint32_t j = js[s];
    const double dist2 = norm2(xs[s] - t.x);
    out[found] = j;
    if (d2) d2[found] = dist2;
    found += static_cast<std::size_t>((dist2 < t.r2) & (j != t.self) & (j < t.limit));
  }
  return found;
}

// Appends the candidates of a cell grid's slots [s0, s1) that `target` accepts to out, and their
// squared distances to d2 unless null; returns how many (scan_candidates in 2D and 3D, vectorised where
// the CPU allows; the scalar scan in other dimensions). out and d2 need room for s1 - s0 + kScanSlack.
template <int D>
std::size_t scan_row(const CellGrid<D>& grid, std::uint32_t s0, std::uint32_t s1, const ScanTarget<D>& target,
                     std::uint32_t* out, double* d2) {
  if constexpr (D == 2 || D == 3) return scan_candidates(grid.sorted.data(), grid.sorted_pos.data(), s0, s1, target, out, d2);
  else return scan_candidates_scalar<D>(grid.sorted.data(), grid.sorted_pos.data(), s0, s1, target, out, d2);
}

// Where particle i's gather list js[0, n) (in cell order) meets i: its first `count` entries come
// before i in cell order (slot[j] < slot_i). Of those below `limit`, the ones whose own gather list
// lacks i (|x_i - x_j|^2 >= 4 h_j^2: i lies outside j's support, the test of j's own search) are
// appended to `lacking` (room for count + kScanSlack entries), `lacking` of them.
struct EarlierPartners {
  std::size_t count, lacking;
};

EarlierPartners earlier_partners(const std::uint32_t* js, std::size_t n, std::uint32_t slot_i, const std::uint32_t* slot,
                                 const Vec<2>& xi, const Vec<2>* pos, const double* h, std::uint32_t limit,
                                 std::uint32_t* lacking);

// The scalar version, in any dimension (earlier_partners' fallback; 3D's only path): the meeting
// point by bisection, the test branch-free (every entry written, the end advanced for lacking ones).
template <int D>
EarlierPartners earlier_partners_scalar(const std::uint32_t* js, std::size_t n, std::uint32_t slot_i,
                                        const std::uint32_t* slot, const Vec<D>& xi, const Vec<D>* pos, const double* h,
                                        std::uint32_t limit, std::uint32_t* lacking) {
  const std::uint32_t* later = std::partition_point(js, js + n, [&](std::uint32_t j) { return slot[j] < slot_i; });
  EarlierPartners r{static_cast<std::size_t>(later - js), 0};
  for (std::size_t k = 0; k < r.count; ++k) {
    const std::uint32_t j = js[k];
    lacking[r.lacking] = j;
    r.lacking += static_cast<std::size_t>((j < limit) & (norm2(xi - pos[j]) >= 4.0 * h[j] * h[j]));
  }
  return r;
}

// Keeps the entries k of idx[0, n) with d2[k] < r2, in order, in place; returns how many. idx needs
// room for n + kScanSlack entries.
std::size_t keep_within(std::uint32_t* idx, const double* d2, std::size_t n, double r2);

// Keeps the entries k of idx[0, n) and d2[0, n) whose pair lies outside the partner's own support,
// d2[k] >= (2 h[idx[k]])^2, in order, in place; returns how many. Writes nothing past entry n.
// (Pairs searched anew, pair_scan.hpp: of i's candidates before it in cell order, the ones whose
// support covers the pair own it.)
std::size_t keep_beyond_supports(std::uint32_t* idx, double* d2, std::size_t n, const double* h);

// The scalar version (keep_beyond_supports' fallback and the vector loop's remainder): entries
// [0, n) of idx and d2 tested, the kept ones written to out_idx and out_d2 (at or before idx, d2:
// in place), branch-free.
inline std::size_t keep_beyond_supports_scalar(const std::uint32_t* idx, const double* d2, std::size_t n,
                                               const double* h, std::uint32_t* out_idx, double* out_d2) {
  std::size_t kept = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t j = idx[k];
    const double r2 = d2[k], s = 2.0 * h[j];
    out_idx[kept] = j;
    out_d2[kept] = r2;
    kept += static_cast<std::size_t>(r2 >= s * s);
  }
  return kept;
}

}  // namespace sphdisk
