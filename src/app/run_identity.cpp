#include "app/run_identity.hpp"

#include <cstdint>
#include <cstdio>

namespace sphdisk {

namespace {

bool decides_results(const std::string& key) {
  for (const char* section : {"problem.", "physics.", "sph.", "integrator."})
    if (key.rfind(section, 0) == 0) return true;
  return false;
}

// FNV-1a, 64 bits: stable across builds and machines (std::hash is not).
void mix(std::uint64_t& h, const std::string& text) {
  for (unsigned char c : text) h = (h ^ c) * 0x100000001b3ULL;
  h = (h ^ 0xffu) * 0x100000001b3ULL;  // separator, so that "ab" + "c" differs from "a" + "bc"
}

}  // namespace

std::string run_identity(const Config& cfg) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const auto& [key, value] : cfg.resolved)
    if (decides_results(key)) mix(h, key), mix(h, value);
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

}  // namespace sphdisk
