#pragma once
// A 3D run's particles seen from above, for the radial analyses (ring_analysis, disc_profiles): the
// positions and velocities in the disc plane (x, y), masses, smoothing lengths, IDs and densities
// as they are. Binning their masses by cylindrical radius integrates the disc vertically; their
// Density stays a volume density (RingComparison::sph_sigma says whether it is a surface density).
#include "core/particles.hpp"

namespace sphdisk {

inline Particles<2> seen_from_above(const Particles<3>& p) {
  Particles<2> q;
  q.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    q.id[i] = p.id[i];
    q.mass[i] = p.mass[i];
    q.h[i] = p.h[i];
    q.rho[i] = p.rho[i];
    for (int c = 0; c < 2; ++c) q.pos[i][c] = p.pos[i][c], q.vel[i][c] = p.vel[i][c], q.acc[i][c] = p.acc[i][c];
  }
  return q;
}

}  // namespace sphdisk
