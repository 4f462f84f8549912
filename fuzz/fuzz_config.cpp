// Fuzz target: any text given as a configuration file must either parse or raise UserError with a
// one-line message; never crash, hang or raise anything else.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "core/config.hpp"
#include "core/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const sphdisk::Config c = sphdisk::parse_config(text, "fuzz.toml", {});
    // What parses must re-parse to the same configuration.
    if (sphdisk::parse_config(c.resolved_toml, "resolved.toml", {}).resolved_toml != c.resolved_toml) std::abort();
  } catch (const sphdisk::UserError& e) {
    if (std::string(e.what()).find('\n') != std::string::npos) std::abort();  // one-line messages only
  }
  return 0;
}
