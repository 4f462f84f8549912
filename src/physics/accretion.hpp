#pragma once
// Accretion onto the central point mass (docs/physics.md sec. 2, "Gravity and accretion"): particles
// that come closer than the accretion radius leave the disc, and their mass and angular momentum
// L_z go to the central object.
#include <cstdint>
#include <vector>

#include "core/particles.hpp"
#include "core/vec.hpp"

namespace sphdisk {

// The specific angular momentum about the z axis, x v_y - y v_x.
template <int D>
double angular_momentum_z(const Vec<D>& x, const Vec<D>& v) {
  return x[0] * v[1] - x[1] * v[0];
}

struct AccretedParticle {
  std::uint64_t id;
  double mass, lz;
};

// Removes the particles inside the accretion radius and returns what their mass and L_z give to the
// central object.
template <int D>
std::vector<AccretedParticle> accrete(Particles<D>& p, double r_acc) {
  std::vector<AccretedParticle> accreted;
  if (r_acc <= 0) return accreted;
  const double r2 = r_acc * r_acc;
  std::vector<std::uint32_t> keep;
  keep.reserve(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (norm2(p.pos[i]) < r2) {
      accreted.push_back({p.id[i], p.mass[i], p.mass[i] * angular_momentum_z(p.pos[i], p.vel[i])});
    } else {
      keep.push_back(static_cast<std::uint32_t>(i));
    }
  }
  if (keep.size() != p.size()) p.gather(keep);
  return accreted;
}

}  // namespace sphdisk
