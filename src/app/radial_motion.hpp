#pragma once
// A 2D particle's motion about the point mass at the origin (docs/physics.md sec. 4 "Diagnostics"),
// shared by the ring's comparison and any disc's profiles: its radius, its radial velocity (with its
// epicycles), its specific angular momentum j = x v_y - y v_x, and the drift of its guiding centre
// r_g = j^2 / (G M), 2 j (dj/dt) / (G M): only the non-central (viscous) force changes j, so this is
// v_r without the epicycles.
#include <cstddef>

#include "core/particles.hpp"

namespace sphdisk {

struct RadialMotion {
  double r, vr, j, drift;
};

inline RadialMotion radial_motion(const Particles<2>& p, std::size_t i, double gm) {
  const auto& x = p.pos[i];
  const auto& v = p.vel[i];
  const auto& a = p.acc[i];
  const double r = norm(x);
  const double j = x[0] * v[1] - x[1] * v[0];
  return {r, (x[0] * v[0] + x[1] * v[1]) / r, j, 2.0 * j * (x[0] * a[1] - x[1] * a[0]) / gm};
}

}  // namespace sphdisk
