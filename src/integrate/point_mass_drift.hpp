#pragma once
// The inner loop of the r-RESPA schemes (leapfrog.cpp, block_leapfrog.cpp): one particle moved over
// dt in the point mass's field alone, by KDK leapfrog substeps of at most factor / Omega (taken at
// the start). The count depends only on the particle's own state, so on no thread or rank count.
#include <algorithm>
#include <cmath>

#include "core/vec.hpp"
#include "integrate/timestep.hpp"
#include "physics/forces.hpp"

namespace sphdisk {

template <int D>
void drift_in_point_mass_field(Vec<D>& x, Vec<D>& v, double dt, double gm, double factor) {
  const double substeps = std::max(1.0, std::ceil(dt / orbital_timestep(norm(x), gm, factor)));
  const double delta = dt / substeps, delta_half = 0.5 * delta;
  Vec<D> g = point_mass_gravity(x, gm);
  for (double s = 0; s < substeps; s += 1) {
    v += g * delta_half;
    x += v * delta;
    g = point_mass_gravity(x, gm);
    v += g * delta_half;
  }
}

}  // namespace sphdisk
