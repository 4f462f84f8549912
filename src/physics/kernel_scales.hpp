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

// Fills scales with the kernel's scales of every particle (ghosts included) that reads(i) names (the
// others are left unset: no pair loop reads them). Returns their data.
template <int D, class Reads = bool (*)(std::size_t)>
const KernelScale* fill_kernel_scales(const Particles<D>& p, KernelType kernel, OverwriteVector<KernelScale>& scales,
                                      const char* phase, Reads reads = [](std::size_t) { return true; }) {
  renew_snug(scales, p.size());
  with_kernel(kernel, [&](auto k) {
    using K = decltype(k);
    par::for_each(p.size(), [&](std::size_t i) {
      if (reads(i)) scales[i] = scale_of(KernelAt<K, D>(p.h[i]));
    }, phase);
  });
  return scales.data();
}

// The same where the pair sums need kernel values (PhysicsParams::needs_kernel_values), else empties
// them and returns null.
template <int D, class Reads = bool (*)(std::size_t)>
const KernelScale* fill_kernel_scales(const Particles<D>& p, const PhysicsParams& phys, OverwriteVector<KernelScale>& scales,
                                      const char* phase, Reads reads = [](std::size_t) { return true; }) {
  if (phys.needs_kernel_values()) return fill_kernel_scales(p, phys.kernel, scales, phase, reads);
  renew_snug(scales, 0);
  return nullptr;
}

}  // namespace sphdisk
