#pragma once
// One global smoothing length for initial conditions given as particles (a user's file without
// sph.smoothing_length): the h for which the mean number of neighbours within 2h is `target`.
// In D dimensions the count grows as h^D, so h is rescaled by (target / mean)^(1/D) until the mean
// is within 1% of the target. Over several processes the counts come from each one's particles
// and ghosts (exact integer sums), so h has the same bits as on one process, and no process ever
// holds all particles.
#include "core/particles.hpp"
#include "domain/particle_domain.hpp"

namespace sphdisk {

// p: this process's particles (decomposed already when there is a domain; ghosts come and go
// inside). domain = nullptr: one process holding all particles.
template <int D>
double calibrate_smoothing_length(Particles<D>& p, double target, ParticleDomain<D>* domain = nullptr);

}  // namespace sphdisk
