#include "neighbours/interaction_lists.hpp"

#include <algorithm>

#include "core/snug_resize.hpp"
#include "parallel/loops.hpp"

namespace sphdisk {

namespace {

struct ScatterPair {
  std::uint32_t target, source;  // source reaches target only through the source's own support
};

constexpr std::size_t kBlock = 1024;

}  // namespace

template <int D>
void build_interaction_lists(const NeighbourLists& gather, const std::vector<Vec<D>>& pos, const std::vector<double>& h,
                             const std::vector<std::uint64_t>& id, NeighbourLists& out) {
  const std::size_t n = pos.size();
  const std::size_t nblocks = (n + kBlock - 1) / kBlock;
  std::vector<std::vector<ScatterPair>> block_pairs(nblocks);

  // Pass 1: the pairs j must receive because i lies inside 2 h_i but outside 2 h_j.
  par::for_each(nblocks, [&](std::size_t b) {
    for (std::size_t i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i) {
      for (const std::uint32_t* it = gather.begin(i); it != gather.end(i); ++it) {
        const std::uint32_t j = *it;
        if (norm2(pos[i] - pos[j]) >= 4.0 * h[j] * h[j]) block_pairs[b].push_back({j, static_cast<std::uint32_t>(i)});
      }
    }
  }, "neighbour_search", 1);

  // Scatter pairs grouped by target (counting sort in block order: deterministic), then by ID.
  std::vector<std::size_t> scatter_start(n + 1, 0);
  for (const auto& pairs : block_pairs)
    for (const ScatterPair& sp : pairs) ++scatter_start[sp.target + 1];
  for (std::size_t i = 0; i < n; ++i) scatter_start[i + 1] += scatter_start[i];
  std::vector<std::uint32_t> scatter(scatter_start[n]);
  {
    std::vector<std::size_t> fill(scatter_start.begin(), scatter_start.end() - 1);
    for (const auto& pairs : block_pairs)
      for (const ScatterPair& sp : pairs) scatter[fill[sp.target]++] = sp.source;
  }

  out.offsets.resize(n + 1);
  out.offsets[0] = 0;
  for (std::size_t i = 0; i < n; ++i)
    out.offsets[i + 1] = out.offsets[i] + gather.count(i) + (scatter_start[i + 1] - scatter_start[i]);
  resize_snug(out.index, out.offsets[n]);

  // Pass 2: write each list.
  par::for_each(n, [&](std::size_t i) {
    std::uint32_t* dst = std::copy(gather.begin(i), gather.end(i), out.index.data() + out.offsets[i]);
    std::uint32_t* extra = dst;
    for (std::size_t k = scatter_start[i]; k < scatter_start[i + 1]; ++k) *dst++ = scatter[k];
    std::sort(extra, dst, [&](std::uint32_t a, std::uint32_t b) { return id[a] < id[b]; });
  }, "neighbour_search");
}

template void build_interaction_lists(const NeighbourLists&, const std::vector<Vec<2>>&, const std::vector<double>&,
                                      const std::vector<std::uint64_t>&, NeighbourLists&);
template void build_interaction_lists(const NeighbourLists&, const std::vector<Vec<3>>&, const std::vector<double>&,
                                      const std::vector<std::uint64_t>&, NeighbourLists&);

}  // namespace sphdisk
