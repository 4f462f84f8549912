#include "core/units.hpp"

#include <cmath>

namespace sphdisk {

UnitSystem UnitSystem::from_solar(double length_rsun, double mass_msun) {
  UnitSystem u;
  u.length_cm = length_rsun * cgs::solar_radius;
  u.mass_g = mass_msun * cgs::solar_mass;
  u.time_s = std::sqrt(u.length_cm * u.length_cm * u.length_cm / (cgs::G * u.mass_g));
  return u;
}

}  // namespace sphdisk
