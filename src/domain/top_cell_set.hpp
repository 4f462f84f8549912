#pragma once
// A set of top cells (domain/decomposition.hpp) with each cell's place among them in the order of
// their linear index (x fastest), found in O(1) through a dense table over the set's bounding box
// in top-cell coordinates. Halo::build keeps a rank's own cells and the cells other ranks listed
// this way: memory as the box's volume, not the whole grid's (whose top cells grow with P).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace sphdisk {

template <int D>
class TopCellSet {
 public:
  static constexpr std::uint32_t kAbsent = std::numeric_limits<std::uint32_t>::max();

  TopCellSet() = default;
  // The set of `cells` (repeats allowed).
  explicit TopCellSet(const std::vector<std::array<int, D>>& cells) {
    if (cells.empty()) return;
    lo_ = hi_ = cells.front();
    for (const auto& t : cells)
      for (std::size_t k = 0; k < D; ++k) lo_[k] = std::min(lo_[k], t[k]), hi_[k] = std::max(hi_[k], t[k]);
    std::size_t volume = 1;
    for (std::size_t k = 0; k < D; ++k) volume *= static_cast<std::size_t>(hi_[k] - lo_[k] + 1);
    table_.assign(volume, kAbsent);
    for (const auto& t : cells) table_[slot(t)] = 0;
    // Places in table order, which is the grid's linear order restricted to the box.
    std::uint32_t next = 0;
    for (std::size_t s = 0; s < volume; ++s)
      if (table_[s] != kAbsent) table_[s] = next++;
    coords_.resize(next);
    for (const auto& t : cells) coords_[table_[slot(t)]] = t;
  }

  std::size_t size() const { return coords_.size(); }
  const std::array<int, D>& coord(std::size_t place) const { return coords_[place]; }
  // The place of top cell t, or kAbsent.
  std::uint32_t place(const std::array<int, D>& t) const {
    if (coords_.empty()) return kAbsent;
    for (std::size_t k = 0; k < D; ++k)
      if (t[k] < lo_[k] || t[k] > hi_[k]) return kAbsent;
    return table_[slot(t)];
  }
  // Whole cells between top cell t and the set's bounding box along each axis (0 inside), as
  // Halo::build measures the gap between two top cells: never more than t's gap to any member.
  std::array<int, D> cells_apart(const std::array<int, D>& t) const {
    std::array<int, D> g{};
    for (std::size_t k = 0; k < D; ++k) g[k] = std::max({0, lo_[k] - t[k] - 1, t[k] - hi_[k] - 1});
    return g;
  }

 private:
  std::size_t slot(const std::array<int, D>& t) const {
    std::size_t s = 0;
    for (std::size_t k = D; k-- > 0;) s = s * static_cast<std::size_t>(hi_[k] - lo_[k] + 1) + static_cast<std::size_t>(t[k] - lo_[k]);
    return s;
  }

  std::array<int, D> lo_{}, hi_{};
  std::vector<std::uint32_t> table_;
  std::vector<std::array<int, D>> coords_;
};

}  // namespace sphdisk
