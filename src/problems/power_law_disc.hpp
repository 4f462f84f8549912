#pragma once
// The power-law disc of Phantom's disc set-up: Sigma = Sigma_0 R^-p between R_in and R_out (sharp
// edges), locally isothermal; in 3D in vertical hydrostatic equilibrium (disc_sampling.hpp).
#include "problems/disc_sampling.hpp"

namespace sphdisk {

struct PowerLawDisc {
  double inner_radius = 1.0, outer_radius = 5.0;  // code units (r0 = 1)
  double sigma_index = 1.0;                       // p
  double mass = 1e-3;                             // code units (M = 1)
};

// Its surface density normalised to the disc's mass: Sigma_0 R^-p on [R_in, R_out], 0 outside.
double power_law_surface_density(const PowerLawDisc& d, double R);

// What sample_disc needs of it (particles, seed, placement and sound speed left to the caller).
DiscSampling power_law_sampling(const PowerLawDisc& d);

}  // namespace sphdisk
