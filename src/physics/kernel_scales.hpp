#pragma once
// Every particle's kernel scale (1/h and sigma_D / h^D, pair_factors.hpp), for the pair loops that
// need kernel values W_ij besides the gradient factors: the mixed correction's sums
// (physics_params.hpp, GradientCorrection::Mixed) and the others' densities (PairDensity::Others).
#include "core/overwrite_vector.hpp"
#include "core/particles.hpp"
#include "core/snug_resize.hpp"
#include "parallel/loops.hpp"
#include "physics/kernels.hpp"
#include "physics/pair_factors.hpp"
#include "physics/physics_params.hpp"

namespace sphdisk {

// Fills scales for every particle (ghosts included) where the pair sums need kernel values
// (PhysicsParams::needs_kernel_values), else empties them. Returns the scales' data or null.
template <int D>
const KernelScale* fill_kernel_scales(const Particles<D>& p, const PhysicsParams& phys, OverwriteVector<KernelScale>& scales,
                                      const char* phase) {
  const bool needed = phys.needs_kernel_values();
  renew_snug(scales, needed ? p.size() : 0);
  if (!needed) return nullptr;
  with_kernel(phys.kernel, [&](auto k) {
    using K = decltype(k);
    par::for_each(p.size(), [&](std::size_t i) { scales[i] = scale_of(KernelAt<K, D>(p.h[i])); }, phase);
  });
  return scales.data();
}

}  // namespace sphdisk
