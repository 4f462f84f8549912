#pragma once
// Random numbers that are the same on every platform for the same seed: the standard library's
// distributions are implementation-defined, so the set-ups and the analysis draw from the 64-bit
// Mersenne Twister's raw output through these.
#include <cmath>
#include <numbers>
#include <random>

namespace sphdisk {

// Uniform double in [0, 1) from the top 53 bits.
inline double uniform01(std::mt19937_64& g) { return static_cast<double>(g() >> 11) * 0x1.0p-53; }

// A standard normal number from two uniforms in [0, 1) (Box-Muller, cosine branch).
inline double standard_normal(double u1, double u2) {
  return std::sqrt(-2.0 * std::log(1.0 - u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

}  // namespace sphdisk
