#pragma once
// Whom a rank's list of ghost-reading top cells must reach (Halo::build). Every rank tells all others
// two boxes: of its particles, with their largest reach, and of the top cells where it has particles
// that read ghosts, with their largest need. A rank's list goes to each rank whose particle box lies
// within the larger of the two radii of its reading box: a box gap is never more than the gap
// between a particle inside one box and a cell inside the other (rounded subtraction is monotone),
// so no rank that could send a ghost misses the list, and a rank hears from its neighbours only.
#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>
#include <vector>

namespace sphdisk {

template <int D>
struct RankBox {
  std::array<double, D> lo, hi;
  double radius = -1.0;  // < 0: empty

  RankBox() {
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
  }
  bool empty() const { return radius < 0; }
  // Widens the box to [a, b] with radius r.
  void include(const std::array<double, D>& a, const std::array<double, D>& b, double r) {
    for (std::size_t k = 0; k < D; ++k) lo[k] = std::min(lo[k], a[k]), hi[k] = std::max(hi[k], b[k]);
    radius = std::max(radius, r);
  }
  // Squared gap to another box (0 where they overlap).
  double gap2(const RankBox& o) const {
    double g2 = 0;
    for (std::size_t k = 0; k < D; ++k) {
      const double g = std::max({0.0, o.lo[k] - hi[k], lo[k] - o.hi[k]});
      g2 += g * g;
    }
    return g2;
  }
};

template <int D>
struct RankBoxes {
  static constexpr std::size_t kValues = 2 * (2 * D + 1);
  RankBox<D> particles, readers;

  std::array<double, kValues> values() const {
    std::array<double, kValues> v{};
    std::size_t n = 0;
    for (const RankBox<D>* b : {&particles, &readers}) {
      for (const double x : b->lo) v[n++] = x;
      for (const double x : b->hi) v[n++] = x;
      v[n++] = b->radius;
    }
    return v;
  }
  // Every rank's boxes from gathered values(), rank after rank.
  static std::vector<RankBoxes> of_values(const std::vector<double>& all) {
    std::vector<RankBoxes> out(all.size() / kValues);
    std::size_t n = 0;
    for (RankBoxes& r : out)
      for (RankBox<D>* b : {&r.particles, &r.readers}) {
        for (double& x : b->lo) x = all[n++];
        for (double& x : b->hi) x = all[n++];
        b->radius = all[n++];
      }
    return out;
  }
};

// The ranks (other than `me`) that must receive me's list of reading cells.
template <int D>
std::vector<std::size_t> list_recipients(const std::vector<RankBoxes<D>>& all, std::size_t me) {
  std::vector<std::size_t> to;
  const RankBox<D>& mine = all[me].readers;
  if (mine.empty()) return to;
  for (std::size_t s = 0; s < all.size(); ++s) {
    const RankBox<D>& theirs = all[s].particles;
    if (s == me || theirs.empty()) continue;
    const double r = std::max(mine.radius, theirs.radius) * (1.0 + 1e-9);
    if (theirs.gap2(mine) < r * r) to.push_back(s);
  }
  return to;
}

}  // namespace sphdisk
