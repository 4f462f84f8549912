#include "integrate/orbit_drift.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/snug_resize.hpp"
#include "core/vector_isa.hpp"
#include "integrate/point_mass_drift.hpp"

// Compiled with -ffp-contract=off (src/CMakeLists.txt): the vector builds must not fuse what the
// baseline one computes in two roundings.
namespace sphdisk {

namespace {

// A run of 2D particles component by component (GCC vectorises the loops below on separate arrays,
// not on the interleaved x, y of Vec<2>): positions before (x0, y0) and after (x, y), velocities,
// stress components, and several = 1 where a particle needs more substeps than the vector loops
// take (kFewSubsteps), else 0; more and which: scratch for the particles that need further substeps.
struct Components {
  double *x0, *y0, *x, *y, *vx, *vy, *s00, *s01, *s10, *s11, *several, *more;
  std::uint32_t* which;
};

// Particles that need more substeps than this over a tick (the innermost ones of a long tick) are
// moved one by one (drift_in_point_mass_field).
constexpr double kFewSubsteps = 16;

namespace baseline_isa {
#include "integrate/orbit_drift_loops.inc"
}  // namespace baseline_isa
#ifdef SPHDISK_X86_VECTOR_DISPATCH
#pragma GCC push_options
#pragma GCC target("avx2")
namespace avx2_isa {
#include "integrate/orbit_drift_loops.inc"
}  // namespace avx2_isa
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("avx512f")
namespace avx512_isa {
#include "integrate/orbit_drift_loops.inc"
}  // namespace avx512_isa
#pragma GCC pop_options
#endif

// Particles [0, n) of a 2D run, on the CPU's widest instruction set (core/vector_isa.hpp); c.several
// says which of them the general routine must move instead.
void substep_2d(Vec<2>* x, Vec<2>* v, Mat<2, ReducedReal>* S, const Components& c, std::size_t n, double dt, double gm,
                double factor) {
  static_assert(sizeof(Vec<2>) == 2 * sizeof(double) && sizeof(Mat<2, ReducedReal>) == 4 * sizeof(ReducedReal),
                "positions and velocities are read as pairs of doubles, stresses as four reals");
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  switch (vector_isa()) {
    case VectorIsa::avx512: return avx512_isa::substep_particles(x, v, S, c, n, dt, gm, factor);
    case VectorIsa::avx2: return avx2_isa::substep_particles(x, v, S, c, n, dt, gm, factor);
    case VectorIsa::baseline: break;
  }
#endif
  baseline_isa::substep_particles(x, v, S, c, n, dt, gm, factor);
}

}  // namespace

template <int D>
void drift_and_turn(Vec<D>* x, Vec<D>* v, Mat<D, ReducedReal>* S, std::size_t n, double dt, double gm, double factor) {
  thread_local std::vector<double> scratch;
  thread_local std::vector<std::uint32_t> which;
  double* several = nullptr;  // null: every particle by the general routine (3D)
  if constexpr (D == 2) {
    double* base = scratch_for(scratch, 16 * n);
    if (which.size() < n) which.resize(n);
    const Components c{base,         base + n,     base + 2 * n, base + 3 * n, base + 4 * n,  base + 5 * n,
                       base + 6 * n, base + 7 * n, base + 8 * n, base + 9 * n, base + 10 * n, base + 11 * n,
                       which.data()};
    substep_2d(x, v, S, c, n, dt, gm, factor);
    several = c.several;
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (several && several[k] == 0.0) continue;
    const Vec<D> from = x[k];
    drift_in_point_mass_field(x[k], v[k], dt, gm, factor);
    S[k] = turned_with_orbit(S[k], from, x[k]);
  }
}

template void drift_and_turn<2>(Vec<2>*, Vec<2>*, Mat<2, ReducedReal>*, std::size_t, double, double, double);
template void drift_and_turn<3>(Vec<3>*, Vec<3>*, Mat<3, ReducedReal>*, std::size_t, double, double, double);

}  // namespace sphdisk
