#pragma once
// The Sedov-Taylor similarity solution of a point explosion of energy E in a uniform ideal gas of
// density rho0 and negligible pressure (Sedov 1959; docs/physics.md sec. 5): a strong shock at
// R(t) = xi0 (E t^2 / rho0)^(1/(j+2)), j = 3 (spherical) or 2 (cylindrical: a 2D run, E per unit
// length). Behind it rho = rho0 D(xi), v = R' U(xi), p = rho0 R'^2 P(xi) with xi = r / R and
// R' = dR/dt = 2 R / ((j + 2) t); D, U, P solve the similarity form of the Euler equations, here
// integrated from the shock's jump conditions inward, and xi0 follows from the energy integral.
#include <vector>

namespace sphdisk {

class SedovSolution {
 public:
  SedovSolution(double gamma, int dimension);

  struct State {
    double rho = 0, v = 0, p = 0;  // density, radial velocity, pressure
  };

  double xi0() const { return xi0_; }
  double shock_radius(double energy, double rho0, double t) const;
  // The state at radius r and time t > 0 (ambient rho0 at rest beyond the shock).
  State at(double r, double energy, double rho0, double t) const;

 private:
  double gamma_;
  int j_;
  double xi0_ = 0;
  // D, U, P on a grid of xi descending from 1 (the shock) to near 0.
  std::vector<double> xi_, d_, u_, p_;
};

}  // namespace sphdisk
