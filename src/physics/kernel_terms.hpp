#pragma once
// The kernel terms of the smoothing-length solve (smoothing_length.hpp): for each candidate at
// distance dist[k], q = dist[k] / h, w[k] = w(q) and dw[k] = D w(q) + q w'(q). The solve's most
// frequent loop (every Newton iterate, every candidate). Compiled three times, for the portable
// baseline (two doubles per instruction), AVX2 (four) and AVX-512 (eight), the widest the CPU has
// chosen at run time (core/vector_isa.hpp). Same bits either way: the loop is the same source, element-wise
// IEEE operations, compiled without floating-point contraction.
#include <cstddef>

namespace sphdisk {

template <class K, int D>
void kernel_terms(const double* dist, double inv_h, std::size_t n, double* w, double* dw);

}  // namespace sphdisk
