// The CPU's double-precision FMA peak per core, measured here rather than quoted, against which the
// force loop's floating-point rate is judged (docs/performance.md,
// "Floating-point rate of the force loop"). Twelve independent chains of fused
// multiply-adds (more than FMA latency x throughput on current x86 cores, so the chains never wait on
// each other), each FMA 2 FLOPs per lane, on the widest vectors the CPU has (AVX-512: 8 lanes, AVX2:
// 4). The values converge to 1 (a <- 0.9999999 a + 1e-7, factors hidden from the compiler): no
// overflow, no subnormals.
//   build/release/bench/fma_peak                       (one thread, then one per core: Threads(2))
// Reports "FLOP/s per thread" (per core where threads <= cores).
#include <benchmark/benchmark.h>

#include <cstdint>

#include "core/vector_isa.hpp"

namespace {
using namespace sphdisk;

constexpr int kChains = 12;
constexpr std::int64_t kRounds = 1 << 20;  // per benchmark iteration

#ifdef SPHDISK_X86_VECTOR_DISPATCH
// W lanes of GCC's vector extension; a * m + c becomes one FMA (this file is compiled with
// -ffp-contract=fast, bench/CMakeLists.txt; the disassembly shows vfmadd on zmm and ymm registers).
template <int W>
struct Lanes;  // (vector_size cannot depend on a template parameter)
template <>
struct Lanes<8> {
  typedef double type __attribute__((vector_size(64)));
};
template <>
struct Lanes<4> {
  typedef double type __attribute__((vector_size(32)));
};

template <int W>
[[gnu::always_inline]] inline double chains(std::int64_t rounds, double mul, double add) {
  using V = typename Lanes<W>::type;
  V a[kChains];
  for (int k = 0; k < kChains; ++k) a[k] = V{} + (1.0 + 1e-3 * k);
  const V m = V{} + mul, c = V{} + add;
  for (std::int64_t r = 0; r < rounds; ++r)
    for (int k = 0; k < kChains; ++k) a[k] = a[k] * m + c;
  double sum = 0;
  for (int k = 0; k < kChains; ++k)
    for (int l = 0; l < W; ++l) sum += a[k][l];
  return sum;
}

__attribute__((target("avx512f"), noinline)) double chains_avx512(std::int64_t rounds, double mul, double add) {
  return chains<8>(rounds, mul, add);
}
__attribute__((target("avx2,fma"), noinline)) double chains_avx2(std::int64_t rounds, double mul, double add) {
  return chains<4>(rounds, mul, add);
}
#endif

void BM_FmaPeak(benchmark::State& state) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  const VectorIsa isa = cpu_vector_isa();
  if (isa == VectorIsa::baseline) {
    state.SkipWithError("no AVX2/FMA on this CPU");
    return;
  }
  const int lanes = isa == VectorIsa::avx512 ? 8 : 4;
  // Factors the compiler cannot see (it folds FMAs of known constants, the whole loop with them).
  volatile double mul = 0.9999999, add = 1e-7;
  for (auto _ : state)
    benchmark::DoNotOptimize(isa == VectorIsa::avx512 ? chains_avx512(kRounds, mul, add) : chains_avx2(kRounds, mul, add));
  // Per thread (Google Benchmark's rate with kAvgThreads is that of all threads together).
  state.counters["FLOP/s per thread"] = benchmark::Counter(
      2.0 * lanes * kChains * static_cast<double>(kRounds) / state.threads(),
      benchmark::Counter::Flags(benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kAvgThreads));
  state.SetLabel(vector_isa_name(isa));
#else
  state.SkipWithError("x86-64 only");
#endif
}

}  // namespace

BENCHMARK(BM_FmaPeak)->Threads(1)->Threads(2)->UseRealTime();

BENCHMARK_MAIN();
