#pragma once
// Particle sets shared by the unit tests.
#include <cmath>
#include <random>

#include "core/particles.hpp"

namespace sphdisk::test {

// n x n square lattice with spacing dx centred on the origin, unit surface density.
inline Particles<2> square_lattice(int n, double dx) {
  Particles<2> p;
  p.resize(static_cast<std::size_t>(n * n));
  for (int iy = 0; iy < n; ++iy)
    for (int ix = 0; ix < n; ++ix) {
      const auto i = static_cast<std::size_t>(iy * n + ix);
      p.id[i] = i + 1;
      p.pos[i] = Vec<2>{{(ix - 0.5 * (n - 1)) * dx, (iy - 0.5 * (n - 1)) * dx}};
      p.mass[i] = dx * dx;
    }
  return p;
}

template <int D>
Particles<D> random_particles(std::size_t n, unsigned seed, bool clustered) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 0.03);
  Particles<D> p;
  p.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    p.id[i] = 1000 + (n - i) * 7;  // IDs not in memory order
    for (int k = 0; k < D; ++k) p.pos[i][k] = clustered && i % 2 ? 0.3 + gauss(g) : u(g);
    for (int k = 0; k < D; ++k) p.vel[i][k] = u(g) - 0.5;
    p.mass[i] = 1.0 / static_cast<double>(n);
  }
  return p;
}

// Indices of particles at least `margin` inside the lattice edge.
inline std::vector<std::size_t> interior(const Particles<2>& p, double half_width, double margin) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (std::abs(p.pos[i][0]) < half_width - margin && std::abs(p.pos[i][1]) < half_width - margin) out.push_back(i);
  return out;
}

}  // namespace sphdisk::test
