#pragma once
// Every particle's kernel scale (1/h and sigma_D / h^D, pair_factors.hpp), for the pair loops that
// need kernel values W_ij besides the gradient factors: the mixed correction's sums
// (physics_params.hpp, GradientCorrection::Mixed), the others' densities (PairDensity::Others) and
// the scatter density (scatter_density.hpp).
#include "core/overwrite_vector.hpp"
#include "core/particles.hpp"
#include "core/snug_resize.hpp"
#include "parallel/loops.hpp"
#include "physics/kernels.hpp"
#include "physics/pair_factors.hpp"
#include "physics/physics_params.hpp"

namespace sphdisk {

// Fills scales for every particle (ghosts included) with the kernel's scales. Returns their data.
template <int D>
const KernelScale* fill_kernel_scales(const Particles<D>& p, KernelType kernel, OverwriteVector<KernelScale>& scales,
                                      const char* phase) {
  renew_snug(scales, p.size());
  with_kernel(kernel, [&](auto k) {
    using K = decltype(k);
    par::for_each(p.size(), [&](std::size_t i) { scales[i] = scale_of(KernelAt<K, D>(p.h[i])); }, phase);
  });
  return scales.data();
}

// The same where the pair sums need kernel values (PhysicsParams::needs_kernel_values), else empties
// them and returns null.
template <int D>
const KernelScale* fill_kernel_scales(const Particles<D>& p, const PhysicsParams& phys, OverwriteVector<KernelScale>& scales,
                                      const char* phase) {
  if (phys.needs_kernel_values()) return fill_kernel_scales(p, phys.kernel, scales, phase);
  renew_snug(scales, 0);
  return nullptr;
}

}  // namespace sphdisk
