#include "physics/list_sums.hpp"

#include "core/vector_isa.hpp"
#include "physics/list_sums_avx512.hpp"

// Compiled with -ffp-contract=off (src/CMakeLists.txt): a product added to a sum must not be fused
// in one path and not the other (the scalar loops here, the AVX-512 ones in list_sums_avx512_2d.cpp
// and list_sums_avx512_3d.cpp, compiled alike, so native builds agree too).

namespace sphdisk {

#ifdef SPHDISK_X86_VECTOR_DISPATCH
using namespace list_avx512;

namespace {

// The scalar gradient loop compiled for AVX2: a pair's eight sums in two instructions, not four.
// (The force loop compiled so was slower; with AVX2 only it runs the scalar loop: docs/design.md,
// "Modes kept and retired".)
template <int D>
[[gnu::target("avx2")]] void gradient_list_avx2(const GradientListData<D>& d, std::uint32_t i, std::span<const std::uint32_t> js,
                                                std::span<const float> F, GradientSums<D>& sum_i) {
  add_gradient_list_scalar(d, i, js, F, sum_i);
}

}  // namespace
#endif

template <int D>
void add_gradient_list(const GradientListData<D>& d, std::uint32_t i, std::span<const std::uint32_t> js,
                       std::span<const float> F, GradientSums<D>& sum_i) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  if (d.scales) return add_gradient_list_scalar(d, i, js, F, sum_i);
  if (vector_isa() == VectorIsa::avx512) return gradient_list_avx512(d, i, js.data(), F.data(), js.size(), sum_i);
  if (vector_isa() == VectorIsa::avx2) return gradient_list_avx2(d, i, js, F, sum_i);
#endif
  add_gradient_list_scalar(d, i, js, F, sum_i);
}

template void add_gradient_list(const GradientListData<2>&, std::uint32_t, std::span<const std::uint32_t>,
                                std::span<const float>, GradientSums<2>&);
template void add_gradient_list(const GradientListData<3>&, std::uint32_t, std::span<const std::uint32_t>,
                                std::span<const float>, GradientSums<3>&);

template <int D>
void add_scatter_list(const ScatterListData<D>& d, std::uint32_t i, std::span<const std::uint32_t> js, double& sum_i) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  if constexpr (D == 2) {
    if (d.kernel == KernelType::Cubic && vector_isa() == VectorIsa::avx512) return scatter_list_avx512(d, i, js.data(), js.size(), sum_i);
  }
#endif
  with_kernel(d.kernel, [&](auto k) { add_scatter_list_scalar<decltype(k)>(d, i, js, sum_i); });
}

template void add_scatter_list(const ScatterListData<2>&, std::uint32_t, std::span<const std::uint32_t>, double&);
template void add_scatter_list(const ScatterListData<3>&, std::uint32_t, std::span<const std::uint32_t>, double&);

void add_force_list(const ForceListData<2>& d, std::uint32_t i, std::span<const std::uint32_t> js, std::span<const float> F,
                    Vec<2>& ai, double& du_i) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
#ifndef SPHDISK_SINGLE_PRECISION_FIELDS
  if (!d.force_correction && vector_isa() == VectorIsa::avx512) {
    if (!d.with_pressure && !d.consistent) return force_list_avx512(d, i, js.data(), F.data(), js.size(), ai);
    if (d.consistent && !d.rho_without_self && !d.correction_shift && !d.sound_speed) {
      if (d.with_pressure) return consistent_force_list_avx512<true>(d, i, js.data(), F.data(), js.size(), ai, du_i);
      return consistent_force_list_avx512<false>(d, i, js.data(), F.data(), js.size(), ai, du_i);
    }
  }
#endif
#endif
  add_force_list_scalar(d, i, js, F, ai, du_i);
}

void add_force_list(const ForceListData<3>& d, std::uint32_t i, std::span<const std::uint32_t> js, std::span<const float> F,
                    Vec<3>& ai, double& du_i) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
#ifndef SPHDISK_SINGLE_PRECISION_FIELDS
  if (d.with_pressure && !d.force_correction && !d.consistent && vector_isa() == VectorIsa::avx512) {
    if (d.sound_speed) return pressure_force_list_avx512<true>(d, i, js.data(), F.data(), js.size(), ai, du_i);
    return pressure_force_list_avx512<false>(d, i, js.data(), F.data(), js.size(), ai, du_i);
  }
  if (d.with_pressure && d.consistent && !d.rho_without_self && !d.correction_shift && !d.sound_speed &&
      vector_isa() == VectorIsa::avx512)
    return consistent_pressure_force_list_avx512(d, i, js.data(), F.data(), js.size(), ai, du_i);
#endif
#endif
  add_force_list_scalar(d, i, js, F, ai, du_i);
}

}  // namespace sphdisk

