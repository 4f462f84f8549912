#pragma once
// Particle sets shared by the unit tests.
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/particles.hpp"
#include "core/vector_isa.hpp"
#include "physics/physics_params.hpp"

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

// A sheared, jittered 40 x 40 lattice (spacing 0.02), so that adaptive h varies, with a shear flow
// and noise in its velocities.
inline Particles<2> sheared_lattice() {
  auto p = square_lattice(40, 0.02);
  std::mt19937_64 g(53);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (auto& x : p.pos) x += Vec<2>{{0.006 * u(g), 0.006 * u(g)}};
  for (std::size_t i = 0; i < p.size(); ++i) p.vel[i] = Vec<2>{{1.5 * p.pos[i][1] + 0.1 * u(g), 0.2 * p.pos[i][0]}};
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

// The discretisations of eq. 6's divergence (physics/physics_params.hpp): the conservative form, the
// same with the force correction, and the consistent form (the default), with the linear gradient
// correction (the default) or the mixed one.
enum class Form { Conservative, ForceCorrected, Consistent, ConsistentMixed };

inline bool is_consistent(Form form) { return form == Form::Consistent || form == Form::ConsistentMixed; }

inline PhysicsParams with_form(PhysicsParams phys, Form form) {
  phys.viscous_force = is_consistent(form) ? ViscousForce::Consistent : ViscousForce::Conservative;
  phys.force_correction = form == Form::ForceCorrected;
  phys.gradient_correction = form == Form::ConsistentMixed ? GradientCorrection::Mixed : GradientCorrection::Linear;
  return phys;
}

inline const char* form_name(Form form) {
  switch (form) {
    case Form::Conservative: return "conservative";
    case Form::ForceCorrected: return "force-corrected";
    case Form::Consistent: return "consistent";
    case Form::ConsistentMixed: return "consistent, mixed correction";
  }
  return "";
}

// Physical viscosity nu and no point mass: the pair terms alone.
inline PhysicsParams viscous_no_gravity(double nu) {
  PhysicsParams phys;
  phys.nu = nu;
  phys.gm = 0.0;
  return phys;
}

// Indices of particles at least `margin` inside the lattice edge.
inline std::vector<std::size_t> interior(const Particles<2>& p, double half_width, double margin) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (std::abs(p.pos[i][0]) < half_width - margin && std::abs(p.pos[i][1]) < half_width - margin) out.push_back(i);
  return out;
}

// After a rate evaluation: sum m a = 0 and sum m (v . a + du/dt) = 0 to round-off, relative to
// sum m |v . a| (exact conservation of momentum and of kinetic + internal energy).
inline void expect_momentum_and_energy_conserved(const Particles<2>& p, const std::string& what) {
  Vec<2> momentum_rate;
  double energy_rate = 0, scale = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    momentum_rate += p.acc[i] * p.mass[i];
    energy_rate += p.mass[i] * (dot(p.vel[i], p.acc[i]) + p.du_dt[i]);
    scale += p.mass[i] * std::abs(dot(p.vel[i], p.acc[i]));
  }
  ASSERT_GT(scale, 0.0) << what;
  EXPECT_LT(std::abs(momentum_rate[0]) + std::abs(momentum_rate[1]), 1e-12 * scale) << what;
  EXPECT_LT(std::abs(energy_rate), 1e-12 * scale) << what;
}

// The vector paths of the hand-dispatched loops (core/vector_isa.hpp) that this CPU runs besides
// the baseline, narrowest first; empty where it has neither AVX2 nor AVX-512.
inline std::vector<VectorIsa> vector_paths() {
  std::vector<VectorIsa> paths;
  for (const VectorIsa isa : {VectorIsa::avx2, VectorIsa::avx512})
    if (cpu_vector_isa() >= isa) paths.push_back(isa);
  return paths;
}

// run() with the dispatched loops capped at `isa`; the cap is lifted afterwards.
template <class Run>
auto on_path(VectorIsa isa, Run&& run) {
  limit_vector_isa(isa);
  auto result = std::forward<Run>(run)();
  limit_vector_isa(VectorIsa::avx512);
  return result;
}

}  // namespace sphdisk::test
