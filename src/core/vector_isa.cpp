#include "core/vector_isa.hpp"

#include <algorithm>

#include "core/named_choice.hpp"

namespace sphdisk {

namespace {

VectorIsa detect() {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  __builtin_cpu_init();  // (this may run before libgcc's own constructor has)
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") ? VectorIsa::avx512
         : __builtin_cpu_supports("avx2")                                      ? VectorIsa::avx2
                                                                               : VectorIsa::baseline;
#else
  return VectorIsa::baseline;
#endif
}

// Asked once, at start-up: vector_isa() is called once per list by the list loops, where a
// function-local static's guard would show in profiles.
const VectorIsa cpu_isa = detect();
VectorIsa in_use = cpu_isa;

}  // namespace

VectorIsa cpu_vector_isa() { return cpu_isa; }

VectorIsa vector_isa() { return in_use; }

void limit_vector_isa(VectorIsa widest) { in_use = std::min(widest, cpu_isa); }

VectorIsa vector_isa_limit_from_name(std::string_view name) {
  static constexpr NamedChoice<VectorIsa> kNames[] = {
      {"auto", VectorIsa::avx512}, {"avx2", VectorIsa::avx2}, {"baseline", VectorIsa::baseline}};
  return choice_from_name<VectorIsa>("run.vector_isa", name, kNames);
}

const char* vector_isa_name(VectorIsa isa) {
  switch (isa) {
    case VectorIsa::avx512: return "avx512";
    case VectorIsa::avx2: return "avx2";
    default: return "baseline";
  }
}

}  // namespace sphdisk
