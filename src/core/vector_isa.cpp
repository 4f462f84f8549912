#include "core/vector_isa.hpp"

namespace sphdisk {

namespace {

bool allowed = true;

bool cpu_has_avx512() {
#ifdef SPHDISK_X86_AVX512_DISPATCH
  static const bool has = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
  return has;
#else
  return false;
#endif
}

}  // namespace

bool use_avx512() { return allowed && cpu_has_avx512(); }

void allow_avx512(bool allow) { allowed = allow; }

}  // namespace sphdisk
