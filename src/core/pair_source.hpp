#pragma once
// What the pair loops of physics/ need of a pair source (neighbours/pair_lists.hpp, pair_scan.hpp,
// tile_half_lists.hpp) and what they tell it besides the list body: for_each_list(f, use,
// trace_label, far_pairs). Here, not in neighbours/, so that the physics loops need no
// neighbour-search header.
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace sphdisk {

// What a pair loop does with the kernel-gradient factors of its pairs (physics/pair_factors.hpp):
// computes them (the density loop) or reads them (the loops after it).
enum class FactorUse { Write, Read };

// Where a pair loop puts the far pairs: after the tiles' pairs (the default), or before them (the
// velocity-gradient sums: so that a particle's sums are complete once the tiles around it have
// passed, and the force loop can follow the gradient loop tile by tile, tile_jobs.hpp).
enum class FarPairs { Last, First };

// A list body as a pair source calls it: particle i, its partners js, and the kernel-gradient
// factors of those pairs (physics/pair_factors.hpp).
using PairListBody = void (*)(std::uint32_t i, std::span<const std::uint32_t> js, std::span<float> factors);

// A pair source: how many particles (the first ones) get new values, its factors made ready for a
// loop that writes them, and every list of pairs visited once (StoredPairs, StoredPairsFormingFactors
// and TiledPairs of neighbours/pair_lists.hpp and tile_half_lists.hpp, ScannedPairs of pair_scan.hpp).
template <class Pairs>
concept PairSource = requires(const Pairs& pairs, PairListBody body) {
  { pairs.writable() } -> std::convertible_to<std::size_t>;
  pairs.prepare_factors();
  pairs.for_each_list(body, FactorUse::Write, std::string_view{}, FarPairs::Last);
};

// A pair source that tells which particles its loops may read (ScannedPairs: the writable ones and
// those with a writable one within reach), so that the per-particle factors the pair terms read are
// formed for those only: with few active particles most are never read.
template <class Pairs>
concept TellsParticlesRead = PairSource<Pairs> && requires(const Pairs& pairs, std::uint32_t i) {
  { pairs.may_read(i) } -> std::convertible_to<bool>;
};

// may_read(i) of a pair source that tells it, else true for every particle.
template <class Pairs>
auto particles_read_by(const Pairs& pairs) {
  if constexpr (TellsParticlesRead<Pairs>) return [&pairs](std::size_t i) { return pairs.may_read(static_cast<std::uint32_t>(i)); };
  else return [](std::size_t) { return true; };
}

// A pair source that can search its pairs once for two loops (ScannedPairs: the velocity gradient
// and the forces, physics/viscous_rates.hpp).
template <class Pairs>
concept JoinsLoops = PairSource<Pairs> && requires { Pairs::kJoinsLoops; };

}  // namespace sphdisk
