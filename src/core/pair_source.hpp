#pragma once
// What the pair loops of physics/ tell a pair source (neighbours/pair_lists.hpp, pair_scan.hpp,
// tile_half_lists.hpp) besides the list body: for_each_list(f, use, trace_label, far_pairs). Here,
// not in neighbours/, so that the physics loops need no neighbour-search header.

namespace sphdisk {

// What a pair loop does with the kernel-gradient factors of its pairs (physics/pair_factors.hpp):
// computes them (the density loop) or reads them (the loops after it).
enum class FactorUse { Write, Read };

// Where a pair loop puts the far pairs: after the tiles' pairs (the default), or before them (the
// velocity-gradient sums: so that a particle's sums are complete once the tiles around it have
// passed, and the force loop can follow the gradient loop tile by tile, tile_jobs.hpp).
enum class FarPairs { Last, First };

}  // namespace sphdisk
