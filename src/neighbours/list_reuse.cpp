#include "neighbours/list_reuse.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "parallel/loops.hpp"

namespace sphdisk {

namespace {

// Distance between two axis-aligned boxes (0 when they overlap).
template <int D>
double box_distance(const Vec<D>& alo, const Vec<D>& ahi, const Vec<D>& blo, const Vec<D>& bhi) {
  double d2 = 0;
  for (int k = 0; k < D; ++k) {
    const double gap = std::max({blo[k] - ahi[k], alo[k] - bhi[k], 0.0});
    d2 += gap * gap;
  }
  return std::sqrt(d2);
}

}  // namespace

template <int D>
void ListReuse<D>::record(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, const std::vector<std::uint64_t>& id) {
  id0_ = id;
  pos0_ = pos;
  first_.clear();
  for (std::size_t c = 0; c < grid.num_cells(); ++c)
    if (grid.offsets[c + 1] > grid.offsets[c]) first_.push_back(grid.offsets[c]);
  first_.push_back(static_cast<std::uint32_t>(grid.sorted.size()));
  recorded_ = true;
}

template <int D>
bool ListReuse<D>::same_particles(const std::vector<std::uint64_t>& id) const {
  return recorded_ && id == id0_;
}

template <int D>
typename ListReuse<D>::Verdict ListReuse<D>::check(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos,
                                                   const Radius& listed, const Radius& support) {
  if (!recorded_) return {false, std::numeric_limits<double>::infinity()};
  const std::size_t nc = first_.size() - 1;
  if (nc == 0) return {true, 0};
  cells_.resize(nc);
  centres_.resize(nc);
  centre_id_.resize(nc);
  ranked_.resize(grid.sorted.size());
  par::for_each(nc, [&](std::size_t c) {
    CellState s;
    const std::uint32_t i0 = grid.sorted[first_[c]];
    s.shift = pos[i0] - pos0_[i0];
    s.lo = s.hi = pos[i0];
    s.slack = s.narrowest = std::numeric_limits<double>::infinity();
    for (std::uint32_t k = first_[c]; k < first_[c + 1]; ++k) {
      const std::uint32_t i = grid.sorted[k];
      s.spread = std::max(s.spread, norm(pos[i] - pos0_[i] - s.shift));
      for (int d = 0; d < D; ++d) {
        s.lo[d] = std::min(s.lo[d], pos[i][d]);
        s.hi[d] = std::max(s.hi[d], pos[i][d]);
      }
      const double si = support(i);
      ranked_[k] = {si, listed(i) - si};
      s.slack = std::min(s.slack, ranked_[k].slack);
      s.support = std::max(s.support, si);
      s.narrowest = std::min(s.narrowest, si);
    }
    // By support, widest first, each with the smallest slack so far (margin() reads a prefix).
    const auto begin = ranked_.begin() + first_[c], end = ranked_.begin() + first_[c + 1];
    std::sort(begin, end, [](const Ranked& a, const Ranked& b) { return a.support > b.support; });
    for (auto it = begin + 1; it < end; ++it) it->slack = std::min(it->slack, (it - 1)->slack);
    s.half_diagonal = 0.5 * norm(s.hi - s.lo);
    cells_[c] = s;
    centres_[c] = 0.5 * (s.lo + s.hi);
    centre_id_[c] = c;
  }, "neighbour_search");

  // Cell pairs whose boxes may be closer than the larger support: centres within
  // support_c + half diagonal of c + the largest half diagonal, found from c's side when c has the
  // larger support.
  double widest_half = 0, mean_reach = 0;
  for (const CellState& s : cells_) widest_half = std::max(widest_half, s.half_diagonal);
  reach_.resize(nc);
  for (std::size_t c = 0; c < nc; ++c) {
    reach_[c] = cells_[c].support + cells_[c].half_diagonal + widest_half;
    mean_reach += reach_[c];
  }
  build_cell_grid(centres_, centre_id_, 0.5 * mean_reach / static_cast<double>(nc), centre_grid_);
  build_neighbour_lists(centre_grid_, centres_, reach_, close_);

  // Largest bound / margin: a cell with itself (pairs inside it), then the close cell pairs, each
  // once: from the cell with the larger support (then the pair is in its list if it matters at
  // all), from the first of two with equal supports.
  const double used = par::reduce(nc, 0.0, [&](std::size_t c) {
    const CellState& a = cells_[c];
    if (!(a.slack > 0)) return std::numeric_limits<double>::infinity();
    double worst = 2.0 * a.spread / a.slack;
    for (const std::uint32_t* it = close_.begin(c); it != close_.end(c); ++it) {
      const CellState& b = cells_[*it];
      if (b.support > a.support || (b.support == a.support && *it < c)) continue;
      const double apart = box_distance<D>(a.lo, a.hi, b.lo, b.hi);
      const double slack = std::min(margin(c, apart), margin(*it, apart));
      if (slack == std::numeric_limits<double>::infinity()) continue;  // no support reaches the other cell
      if (!(slack > 0)) return std::numeric_limits<double>::infinity();
      worst = std::max(worst, (a.spread + b.spread + norm(a.shift - b.shift)) / slack);
    }
    return worst;
  }, [](double x, double y) { return std::max(x, y); });
  return {used < 1.0, used};
}

// The smallest slack of cell c's particles whose support exceeds `apart` (infinite if none): only
// they can have a partner in a cell `apart` away within their support.
template <int D>
double ListReuse<D>::margin(std::size_t c, double apart) const {
  const CellState& s = cells_[c];
  if (apart < s.narrowest) return s.slack;  // every particle's (the common case: adjacent cells)
  double slack = std::numeric_limits<double>::infinity();
  for (std::uint32_t k = first_[c]; k < first_[c + 1] && ranked_[k].support > apart; ++k) slack = ranked_[k].slack;
  return slack;
}

template <int D>
std::size_t ListReuse<D>::bytes() const {
  return id0_.capacity() * sizeof(std::uint64_t) + pos0_.capacity() * sizeof(Vec<D>) + first_.capacity() * sizeof(std::uint32_t) +
         cells_.capacity() * sizeof(CellState) + ranked_.capacity() * sizeof(Ranked) + centres_.capacity() * sizeof(Vec<D>) +
         centre_id_.capacity() * sizeof(std::uint64_t) + reach_.capacity() * sizeof(double) + centre_grid_.bytes() +
         close_.bytes();
}

template class ListReuse<2>;
template class ListReuse<3>;

}  // namespace sphdisk
