#pragma once
// Where a result came from: the code version (the source tree's git commit, taken at every
// build) and the build's options, written into every snapshot's Header and printed by
// `sphdisk --version`, as SWIFT and Phantom record theirs.
#include <string>
#include <string_view>

namespace sphdisk {

std::string_view code_version();  // e.g. "0.1.0 (git 2bf6a9e1c0d4-dirty)"; generated (cmake/write_build_info.cmake)
std::string build_options();      // compiler, build type and the options that change results or speed

}  // namespace sphdisk
