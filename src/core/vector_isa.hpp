#pragma once
// Which vector instructions the few hand-dispatched loops use (neighbours/candidate_scan.cpp,
// physics/kernel_terms.cpp): AVX-512 where the CPU has it, asked at run time, so that the portable
// default build uses it too; the baseline code elsewhere. Both paths give the same bits (each of
// those files says why), so results do not depend on which ran.
#if defined(__x86_64__) && defined(__GNUC__)
#define SPHDISK_X86_AVX512_DISPATCH 1
#endif

namespace sphdisk {

// Whether the dispatched loops use AVX-512 (the CPU has AVX-512F and -VL, and it is not switched off).
bool use_avx512();
// Switches AVX-512 off (false) or back on where the CPU has it: for the tests and benchmarks that
// compare the two paths. Not to be called while a loop runs.
void allow_avx512(bool allow);

}  // namespace sphdisk
