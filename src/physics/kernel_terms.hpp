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

// dist[k] = sqrt(dist2[k]): the candidates' distances from the squared ones the search hands over,
// dispatched the same way (square roots are correctly rounded, so every path gives the same bits).
// Two-wide, this loop held over half of the solve's samples on an AMD EPYC with AVX-512.
void square_roots(const double* dist2, std::size_t n, double* dist);

}  // namespace sphdisk
