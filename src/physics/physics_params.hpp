#pragma once
// Physical parameters in code units (G = M = r0 = 1 for the ring; see core/units.hpp).

namespace sphdisk {

enum class EquationOfState { None, Isothermal };

struct PhysicsParams {
  double gm = 1.0;                // G * M of the central point mass
  double nu = 0.0;                // kinematic shear viscosity nu = eta / rho (constant, P98 sec. 3.2)
  double nu_bulk = 0.0;           // kinematic bulk viscosity zeta / rho (P98 eq. 2; zero in the paper)
  EquationOfState eos = EquationOfState::None;  // None: pressureless, as in the ring test (P98 5.2)
  double sound_speed = 0.0;       // isothermal sound speed c_s, P = c_s^2 rho
  bool evolve_energy = false;     // integrate du/dt (viscous heating, pressure work)
  double accretion_radius = 0.0;  // particles with r < r_acc are accreted by the central mass
  bool gradient_correction = true;  // discretisation: linear-exact velocity gradient (viscous_stress.hpp)
  bool force_correction = false;    // discretisation: moment-corrected, pair-symmetrised kernel gradient in eq. 6 (moment_correction.hpp)
};

inline double pressure(const PhysicsParams& p, double rho) {
  return p.eos == EquationOfState::Isothermal ? p.sound_speed * p.sound_speed * rho : 0.0;
}

}  // namespace sphdisk
