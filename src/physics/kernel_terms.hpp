#pragma once
// The kernel terms of the smoothing-length solve (smoothing_length.hpp): for each candidate at
// distance dist[k], q = dist[k] / h, w[k] = w(q) and dw[k] = D w(q) + q w'(q), and their sums
// sum_k m_k w[k] and sum_k m_k dw[k] (m_k = mass[k], or 1 where mass is null: equal masses factored
// out), each as four partial sums (lane l takes k = l, l + 4, ... in order, from +0) added as
// (s0 + s1) + (s2 + s3). The solve's most frequent loop (every Newton iterate, every candidate).
// Compiled three times, for the portable baseline (two doubles per instruction), AVX2 (four) and
// AVX-512 (eight), the widest the CPU has chosen at run time (core/vector_isa.hpp). Same bits
// either way: the loops are the same source, element-wise IEEE operations, compiled without
// floating-point contraction; the four partial sums are one vector of four lanes, so that order
// costs one vector addition per four candidates instead of four scalar ones.
#include <cstddef>

namespace sphdisk {

struct KernelSums {
  double w, dw;
};
template <class K, int D>
KernelSums kernel_sums(const double* dist, const double* mass, double inv_h, std::size_t n, double* w, double* dw);

// dist[k] = sqrt(dist2[k]): the candidates' distances from the squared ones the search hands over,
// dispatched the same way (square roots are correctly rounded, so every path gives the same bits).
// Two-wide, this loop would dominate the solve's time (docs/performance.md,
// "Vector loops (AVX-512 and AVX2)").
void square_roots(const double* dist2, std::size_t n, double* dist);

}  // namespace sphdisk
