#pragma once
// toml++ with its internal checks kept on in every build. In release builds toml++ 3.3 turns them
// into compiler assumptions, so a malformed table header such as "[#" is undefined behaviour
// (found by fuzzing, see fuzz/ and tests/fuzz_regressions/). Here a failed check throws, and the
// configuration parser reports invalid TOML. Include this header, never <toml++/toml.h> directly,
// so every translation unit sees the same definitions.
#include <stdexcept>

namespace sphdisk {
struct TomlCheckFailed : std::runtime_error {
  TomlCheckFailed() : std::runtime_error("toml++ internal check failed") {}
};
// Throws TomlCheckFailed. (Inside toml++'s few noexcept functions this ends the program, as the
// library's own assert would; the parser paths that fuzzing reached are not noexcept.)
[[noreturn]] inline void toml_check_failed() { throw TomlCheckFailed(); }
}  // namespace sphdisk

#pragma push_macro("NDEBUG")
#undef NDEBUG
#define TOML_ASSERT(expr)                          \
  do {                                             \
    if (!(expr)) ::sphdisk::toml_check_failed();   \
  } while (0)
#include <toml++/toml.h>
#pragma pop_macro("NDEBUG")
