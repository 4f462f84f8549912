#include "core/vector_isa.hpp"

#include <algorithm>

namespace sphdisk {

namespace {

VectorIsa cap = VectorIsa::avx512;

}  // namespace

VectorIsa cpu_vector_isa() {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  static const VectorIsa has = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") ? VectorIsa::avx512
                               : __builtin_cpu_supports("avx2")                                      ? VectorIsa::avx2
                                                                                                     : VectorIsa::baseline;
  return has;
#else
  return VectorIsa::baseline;
#endif
}

VectorIsa vector_isa() { return std::min(cap, cpu_vector_isa()); }

void limit_vector_isa(VectorIsa widest) { cap = widest; }

const char* vector_isa_name(VectorIsa isa) {
  switch (isa) {
    case VectorIsa::avx512: return "avx512";
    case VectorIsa::avx2: return "avx2";
    default: return "baseline";
  }
}

}  // namespace sphdisk
