#pragma once
// The point mass's part of a block step for all particles at once (block_leapfrog.cpp): each
// particle moved over dt in the point mass's field (drift_in_point_mass_field) and its stored
// stress turned with its orbit (turned_with_orbit). This loop runs over every particle at every
// tick where some step ends, so it must not be scalar (docs/performance.md, "Block timesteps"). In
// 2D the loops are written without branches and compile to vector code (dispatched at run time to
// AVX2 or AVX-512, core/vector_isa.hpp): every particle's first substep in one pass, the further
// ones (up to 16; a long tick takes several for most particles) in passes over those that need them;
// the few innermost particles that need more are moved by the general routine. The same operations
// on each particle either way (orbit_drift.cpp is compiled without floating-point contraction), so
// the same bits on every path and as the routine alone.
#include <cstddef>

#include "core/particles.hpp"
#include "core/vec.hpp"

namespace sphdisk {

// S <- R S R^T for the rotation about z that takes the direction of `from` to that of `to` (x-y
// components; z untouched in 3D). S in its storage form (core/particles.hpp), turned in double.
// Unchanged where either position is at the origin.
template <int D, class T>
Mat<D, T> turned_with_orbit(const Mat<D, T>& S, const Vec<D>& from, const Vec<D>& to) {
  const double norms = std::sqrt((from[0] * from[0] + from[1] * from[1]) * (to[0] * to[0] + to[1] * to[1]));
  const double c = (from[0] * to[0] + from[1] * to[1]) / norms, s = (from[0] * to[1] - from[1] * to[0]) / norms;
  // R = [[c, -s], [s, c]] (and 1 for z): R turns rows 0 and 1 of S, R^T columns 0 and 1 of R S; in
  // 3D row and column 2 pass through. The products of R S R^T written out, without those by the
  // rotation's zeros and its one (a sum of exactly zero may differ in its sign).
  const Mat<D> a = as_double(S);
  Mat<D> t = a;  // R S
  for (int k = 0; k < D; ++k) {
    t(0, k) = c * a(0, k) + -s * a(1, k);
    t(1, k) = s * a(0, k) + c * a(1, k);
  }
  Mat<D> m = t;  // (R S) R^T
  for (int i = 0; i < D; ++i) {
    m(i, 0) = t(i, 0) * c + t(i, 1) * -s;
    m(i, 1) = t(i, 0) * s + t(i, 1) * c;
  }
  Mat<D, T> out;
  store(out, m);
  return norms > 0 ? out : S;
}

// Particles [0, n): positions x, velocities v (after the opening kick) moved over dt, stresses S
// turned.
template <int D>
void drift_and_turn(Vec<D>* x, Vec<D>* v, Mat<D, ReducedReal>* S, std::size_t n, double dt, double gm, double factor);

}  // namespace sphdisk
