// The fuzz targets are built apart from the project (clang, no version generator): the snapshot
// and checkpoint writers they link name this in place of a code version.
#include "core/build_info.hpp"

namespace sphdisk {

std::string_view code_version() { return "fuzz target"; }
std::string build_options() { return "fuzz target"; }

}  // namespace sphdisk
