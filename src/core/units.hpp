#pragma once
// Unit system. The interface (configuration, documentation) uses solar masses, solar radii and
// seconds; inside, code units have G = M = r0 = 1 (length unit r0, mass unit M, time unit
// sqrt(r0^3 / (G M))). Every output records the cgs value of each code unit (GADGET convention).
namespace sphdisk {

namespace cgs {
inline constexpr double G = 6.67430e-8;           // CODATA 2018, cm^3 g^-1 s^-2
inline constexpr double solar_mass = 1.98841e33;  // g: IAU 2015 nominal GM_sun = 1.3271244e26 cm^3 s^-2 over G
inline constexpr double solar_radius = 6.957e10;  // cm (IAU 2015 nominal)
}  // namespace cgs

struct UnitSystem {
  double length_cm;  // code length unit in cm
  double mass_g;     // code mass unit in g
  double time_s;     // code time unit in s
  double velocity_cm_per_s() const { return length_cm / time_s; }

  // Code units with G = 1 from a length (in solar radii) and a mass (in solar masses).
  static UnitSystem from_solar(double length_rsun, double mass_msun);
};

}  // namespace sphdisk
