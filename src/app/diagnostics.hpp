#pragma once
// Global diagnostics of the particle set (docs/physics.md sec. 4 "Diagnostics"): mass, energies and
// the angular momentum L_z, summed with the deterministic reduction of the parallel layer.
#include "core/particles.hpp"

namespace sphdisk {

struct GlobalSums {
  double mass = 0;
  double kinetic_energy = 0;
  double internal_energy = 0;
  double angular_momentum = 0;  // L_z = sum m (x v_y - y v_x)
  GlobalSums operator+(const GlobalSums& o) const {
    return {mass + o.mass, kinetic_energy + o.kinetic_energy, internal_energy + o.internal_energy,
            angular_momentum + o.angular_momentum};
  }
};

template <int D>
double angular_momentum_z(const Vec<D>& x, const Vec<D>& v) {
  return x[0] * v[1] - x[1] * v[0];
}

template <int D>
GlobalSums global_sums(const Particles<D>& p, bool energy);

}  // namespace sphdisk
