#include "symmetric_sequential.hpp"

#include <algorithm>
#include <cmath>

#include "physics/forces.hpp"
#include "physics/viscous_stress.hpp"

namespace sphdisk::bench {

namespace {

// Half lists over the forward half of the stencil: the rest of i's own row of cells after i, and
// the full rows of cells above. Candidates come in cell order, as in the full lists.
void build_half_lists(const CellGrid<2>& g, double radius, NeighbourLists& nl) {
  const std::size_t n = g.sorted.size();
  const double r2 = radius * radius;
  const int reach = static_cast<int>(std::ceil(radius / g.cell_size - 1e-12));
  std::vector<std::uint32_t> slot_of(n);  // sorted slot of particle i
  for (std::size_t s = 0; s < n; ++s) slot_of[g.sorted[s]] = static_cast<std::uint32_t>(s);
  nl.offsets.assign(n + 1, 0);
  nl.index.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec<2> xi = g.sorted_pos[slot_of[i]];
    const int cx = g.coord(xi[0], 0), cy = g.coord(xi[1], 1);
    const int x0 = std::max(cx - reach, 0), x1 = std::min(cx + reach, g.dims[0] - 1);
    for (int y = cy; y <= std::min(cy + reach, g.dims[1] - 1); ++y) {
      std::uint32_t s0 = g.offsets[g.linear({x0, y})];
      const std::uint32_t s1 = g.offsets[g.linear({x1, y}) + 1];
      if (y == cy) s0 = slot_of[i] + 1;  // same row: only what follows i
      // Branch-free append, as in the parallel code's search (neighbour_lists.cpp).
      std::size_t end = nl.index.size();
      nl.index.resize(end + (s1 > s0 ? s1 - s0 : 0));
      for (std::uint32_t s = s0; s < s1; ++s) {
        nl.index[end] = g.sorted[s];
        end += static_cast<std::size_t>(norm2(g.sorted_pos[s] - xi) < r2);
      }
      nl.index.resize(end);
    }
    nl.offsets[i + 1] = nl.index.size();
  }
}

}  // namespace

void SymmetricSequential::evaluate(Particles<2>& p, double h, const PhysicsParams& phys) {
  const KernelAt<CubicSpline, 2> kern(h);
  const std::size_t n = p.size();
  build_cell_grid(p.pos, p.id, h, grid);
  build_half_lists(grid, 2.0 * h, half);

  // Same economy as the parallel code: kernel-gradient factors computed once per pair, in the
  // density loop, in single precision.
  factors.resize(half.total());
  for (std::size_t i = 0; i < n; ++i) p.rho[i] = p.mass[i] * kern.W(0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = half.offsets[i]; k < half.offsets[i + 1]; ++k) {
      const std::uint32_t j = half.index[k];
      const double r = norm(p.pos[i] - p.pos[j]);
      const double w = kern.W(r);
      factors[k] = static_cast<float>(kern.dW_over_r(r));
      p.rho[i] += p.mass[j] * w;
      p.rho[j] += p.mass[i] * w;
    }

  std::vector<GradientSums<2>> g(n);  // V and the moment matrix M, as in viscous_stress.hpp
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = half.offsets[i]; k < half.offsets[i + 1]; ++k) {
      const std::uint32_t j = half.index[k];
      const Vec<2> dx = p.pos[i] - p.pos[j];
      const double f = static_cast<double>(factors[k]);
      const Vec<2> dv = p.vel[j] - p.vel[i];
      const double fi = f * p.mass[j] / p.rho[j], fj = f * p.mass[i] / p.rho[i];
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
          g[i].V(a, b) += fi * dv[a] * dx[b];  // (v_j - v_i) grad_i W
          g[j].V(a, b) += fj * dv[a] * dx[b];  // (v_i - v_j) grad_j W = (v_j - v_i) grad_i W
          g[i].M(a, b) -= fi * dx[a] * dx[b];  // dx dx is even in the pair
          g[j].M(a, b) -= fj * dx[a] * dx[b];
        }
    }
  for (std::size_t i = 0; i < n; ++i) {
    // (The linear correction, whichever phys names: this variant times the conservative force's loops.)
    p.stress[i] = kinematic_stress(phys.gradient_correction != GradientCorrection::None ? corrected_gradient(g[i]) : g[i].V, phys.nu, phys);
    p.acc[i] = point_mass_gravity(p.pos[i], phys.gm);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double inv_rho_i = 1.0 / p.rho[i];
    for (std::size_t k = half.offsets[i]; k < half.offsets[i + 1]; ++k) {
      const std::uint32_t j = half.index[k];
      const Vec<2> gradW = (p.pos[i] - p.pos[j]) * static_cast<double>(factors[k]);
      const double inv_rho_j = 1.0 / p.rho[j];  // one division per pair, against two multiplies per pair for
                                                 // the parallel code's factored sum
      Mat<2> T;  // (S_i / rho_j + S_j / rho_i): the pair's symmetric part, eq. 6
      for (std::size_t c = 0; c < 4; ++c) T.c[c] = p.stress[i].c[c] * inv_rho_j + p.stress[j].c[c] * inv_rho_i;
      const Vec<2> f = contract(T, gradW);
      p.acc[i] += f * p.mass[j];
      p.acc[j] -= f * p.mass[i];
    }
  }
}

}  // namespace sphdisk::bench
