#pragma once
// Global diagnostics of the particle set (docs/physics.md sec. 4 "Diagnostics"): mass, energies and
// the angular momentum L_z over all ranks, summed with the same bits for any thread and rank count
// (parallel/order_free_sum.hpp); and the search for a non-finite value that stops a run.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include "core/particles.hpp"
#include "parallel/communicator.hpp"
#include "parallel/loops.hpp"
#include "physics/accretion.hpp"  // angular_momentum_z

namespace sphdisk {

struct GlobalSums {
  double mass = 0;
  double kinetic_energy = 0;
  double internal_energy = 0;
  double angular_momentum = 0;  // L_z = sum m (x v_y - y v_x)
};

template <int D>
GlobalSums global_sums(const Communicator& comm, const Particles<D>& p, bool energy);  // collective

// A non-finite value, naming particle, field and step ("" when all are finite): of the fields, the one
// most likely the cause (position, then velocity, acceleration, internal energy: a bad position
// spreads to its neighbours' rates within a step), and of the particles with it the lowest ID, so
// that the line does not depend on the particles' order.
template <int D>
std::string find_non_finite(const Particles<D>& p, long long step) {
  static constexpr const char* kFields[] = {"position", "velocity", "acceleration", "internal energy"};
  constexpr int kFinite = 4;
  const auto worst_field = [&](std::size_t i) {
    int f = kFinite;
    if (!p.u.empty() && !std::isfinite(p.u[i])) f = 3;  // (no internal energy without an energy equation)
    for (int k = 0; k < D; ++k) {
      if (!std::isfinite(p.acc[i][k])) f = std::min(f, 2);
      if (!std::isfinite(p.vel[i][k])) f = std::min(f, 1);
      if (!std::isfinite(p.pos[i][k])) f = 0;
    }
    return f;
  };
  using Found = std::pair<int, std::uint64_t>;  // (field, particle ID): the least is reported
  const Found none{kFinite, 0};
  const Found bad = par::reduce(
      p.size(), none, [&](std::size_t i) { return Found{worst_field(i), static_cast<std::uint64_t>(p.id[i])}; },
      [](const Found& a, const Found& b) { return std::min(a, b); });
  if (bad.first == kFinite) return "";
  return "non-finite " + std::string(kFields[bad.first]) + " of particle ID " + std::to_string(bad.second) + " at step " +
         std::to_string(step);
}

}  // namespace sphdisk
