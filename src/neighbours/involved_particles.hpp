#pragma once
// The particles a partial evaluation (block timesteps: only the first `active` particles get new
// rates) involves: the active ones and every inactive particle that may interact with one. With
// block timesteps most evaluations have a few hundred active particles among 1e5 or more, and
// working on all of them (cell grid, tile order, lists, per-particle passes) costs far more than
// the active particles' own pairs (docs/performance.md, "Block timesteps"). SWIFT restricts its
// tasks to active cells for the same reason.
//
// An inactive particle j is involved when it lies within radius[i] of an active particle i (the
// caller's search radius around i: its h solve's candidates and its own support) or an active
// particle lies within j's own support 2 h_j (pairs that only j's support covers, pair_lists.hpp).
// Both tests run on a coarse grid over the active particles' reach: each active particle marks the
// cells its radius touches, and a prefix-count table of the active particles per cell answers
// whether any lies in the cells around j. The tests are conservative: they may take particles that
// interact with none (these only add candidates that every search rejects), never miss one.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/vec.hpp"

namespace sphdisk {

// Fills `members` with 0 .. active - 1 followed by the involved inactive particles in increasing
// index order. radius: one per active particle (> 0). h: every particle's smoothing length (only
// the inactive ones' are read).
template <int D>
void involved_particles(const std::vector<Vec<D>>& pos, const std::vector<double>& h, std::size_t active,
                        const std::vector<double>& radius, std::vector<std::uint32_t>& members);

}  // namespace sphdisk
