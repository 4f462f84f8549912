#pragma once
// The Sedov-Taylor blast wave's initial conditions (docs/physics.md sec. 5): a uniform cube (a square in 2D) of side 1 and mass 1, centred on the origin, with particles
// on a cubic lattice, at rest, with a small uniform internal energy, and the blast energy shared
// equally by the particles within the radius that holds about `central_particles` of them. No
// point mass: the particles feel only their pressure and viscosities.
#include <cstddef>

#include "core/particles.hpp"

namespace sphdisk {

struct SedovBlast {
  std::size_t particles = 0;      // about: the lattice has round(N^(1/D)) particles per side
  double energy = 1.0;            // E, put into the central particles
  double gamma = 5.0 / 3.0;       // adiabatic index
  double central_particles = 60;  // about how many particles share E (the kernel's neighbour number)
  // The ambient gas's pressure over E per unit volume: small, so that the shock stays strong.
  static constexpr double kAmbientPressure = 1e-5;
};

// Lattice points per side, and their spacing (the cube has side 1).
template <int D>
std::size_t sedov_lattice_side(const SedovBlast& s);

// The radius within which the blast energy is put: that of a sphere (circle) holding
// central_particles lattice cells.
template <int D>
double sedov_blast_radius(const SedovBlast& s);

// Share `share` of `shares` of the particles: lattice points share, share + shares, ... (IDs from 1).
template <int D>
Particles<D> make_sedov_blast(const SedovBlast& s, std::size_t share = 0, std::size_t shares = 1);

}  // namespace sphdisk
