#include "core/build_info.hpp"

#include "core/particles.hpp"

namespace sphdisk {

std::string build_options() {
  std::string s = SPHDISK_COMPILER " " SPHDISK_BUILD_TYPE;
#ifdef SPHDISK_HAVE_OPENMP
  s += ", OpenMP";
#endif
#ifdef SPHDISK_HAVE_MPI
  s += ", MPI";
#endif
#ifdef SPHDISK_NATIVE_BUILD
  s += ", -march=native";
#endif
  if (kSinglePrecisionFields) s += ", single-precision fields";
  return s;
}

}  // namespace sphdisk
