#pragma once
// Which vector instructions the few hand-dispatched loops use (neighbours/candidate_scan.cpp,
// physics/kernel_terms.cpp, list_factors.cpp, list_sums.cpp): the widest of AVX-512, AVX2 and the
// baseline (SSE2) that the CPU has, asked at run time, so that the portable default build uses them
// too (AVX2 alone: e.g. AMD EPYC up to Zen 3, common in clusters). Every path gives the same bits
// (each of those files says why), so results do not depend on which ran.
#if defined(__x86_64__) && defined(__GNUC__)
#define SPHDISK_X86_VECTOR_DISPATCH 1
#endif

#include <string_view>

namespace sphdisk {

// Ordered by width: a limit of avx2 allows avx2 and baseline.
enum class VectorIsa { baseline = 0, avx2 = 1, avx512 = 2 };

// The widest ISA the CPU has (AVX-512: F and VL).
VectorIsa cpu_vector_isa();
// What the dispatched loops use: the CPU's widest, capped by limit_vector_isa.
VectorIsa vector_isa();
// Caps the dispatched loops at `widest` (baseline: the scalar/SSE2 code), for the tests and
// benchmarks that compare the paths; avx512 lifts the cap. Not to be called while a loop runs.
void limit_vector_isa(VectorIsa widest);
// run.vector_isa's names: "auto" (no cap: avx512), "avx2", "baseline".
VectorIsa vector_isa_limit_from_name(std::string_view name);
// "baseline", "avx2", "avx512".
const char* vector_isa_name(VectorIsa isa);

}  // namespace sphdisk
