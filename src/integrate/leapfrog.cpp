// Kick-drift-kick leapfrog (docs/physics.md sec. 3). Viscous accelerations depend on velocity, so the
// rates at the end of the drift are evaluated with the predicted velocity v_half + a_old dt/2 and
// then used for the closing kick (as in Phantom).
//
// Scheme::Respa substeps the point mass's gravity inside each hydrodynamic step (r-RESPA,
// Tuckerman, Berne & Martyna 1992; Phantom's step_extern does the same):
//   v += a_hydro dt/2                                 hydro half kick (rates of the last evaluation)
//   n_i times, delta_i = dt / n_i:                    KDK leapfrog in the point-mass field alone
//     v += g(x) delta_i/2;  x += v delta_i;  v += g(x) delta_i/2
//   evaluate a_hydro at the new positions, velocities predicted with + a_hydro_old dt/2
//   v += a_hydro_new dt/2                             hydro half kick
// Why: the point-mass field is cheap and stiff near the centre, the SPH forces are expensive and
// vary slowly. With gravity in the force criterion sqrt(h/|a|) the plain leapfrog's global step is
// set by |g|, not by the SPH forces; here the SPH forces are evaluated on their own step
// (particle_timestep on the SPH acceleration, timestep.hpp) and each particle follows its orbit with its own number of
// substeps n_i = ceil(dt / (C_sub / Omega_i)), which depends only on its own state (so not on
// thread or rank count). Both parts are symplectic KDK schemes: no secular drift of Kepler orbits.
// acc then holds the hydrodynamic acceleration only (RateSource::include_gravity(false)).
#include <algorithm>
#include <cmath>

#include "integrate/integrator.hpp"
#include "integrate/point_mass_drift.hpp"
#include "physics/viscosity_switch.hpp"

namespace sphdisk {

template <int D>
class Leapfrog final : public Integrator<D> {
 public:
  Leapfrog(const IntegratorParams& params, RateSource<D>& rates)
      : params_(params), rates_(rates), substep_gravity_(params.scheme == Scheme::Respa) {
    rates_.include_gravity(!substep_gravity_);
  }

  void start(Particles<D>& p) override { rates_.evaluate(p); }

  double step(Particles<D>& p, double dt_cap) override {
    const PhysicsParams& phys = rates_.physics();
    const TimestepFactors& f = params_.factors;
    // with gravity substepped, acc is the SPH part only: the step is the SPH forces' own
    const double dt = std::min({dt_cap, params_.dt_max, rates_.global_min(explicit_timestep(p, phys, f))});
    const double half = 0.5 * dt;
    const bool energy = phys.evolve_energy;
    const std::size_t n = p.size();
    v_half_.resize(n);
    u_half_.resize(energy ? n : 0);
    {
    ScopedPhase timer(rates_.timers(), "integration");
    par::for_each(n, [&](std::size_t i) {
      v_half_[i] = p.vel[i] + p.acc[i] * half;          // kick
      if (substep_gravity_) {
        drift_in_point_mass_field(p.pos[i], v_half_[i], dt, phys.gm, f.substep);
      } else {
        p.pos[i] += v_half_[i] * dt;                    // drift
      }
      p.vel[i] = v_half_[i] + p.acc[i] * half;          // predicted velocity for the rates
      if (energy) {
        u_half_[i] = p.u[i] + p.du_dt[i] * half;
        p.u[i] = u_half_[i] + p.du_dt[i] * half;
      }
    }, "integration");
    }
    rates_.evaluate(p);
    ScopedPhase timer(rates_.timers(), "integration");
    const bool switching = phys.artificial_viscosity() && phys.av_switch;
    par::for_each(n, [&](std::size_t i) {
      p.vel[i] = v_half_[i] + p.acc[i] * half;          // kick
      if (energy) p.u[i] = u_half_[i] + p.du_dt[i] * half;
      if (switching) advance_viscosity_switch(p, i, dt, phys);
    }, "integration");
    return dt;
  }

  std::size_t bytes() const override { return v_half_.capacity() * sizeof(Vec<D>) + u_half_.capacity() * sizeof(double); }

 private:
  IntegratorParams params_;
  RateSource<D>& rates_;
  bool substep_gravity_;
  std::vector<Vec<D>> v_half_;
  std::vector<double> u_half_;
};

template <int D>
std::unique_ptr<Integrator<D>> make_leapfrog(const IntegratorParams& params, RateSource<D>& rates) {
  return std::make_unique<Leapfrog<D>>(params, rates);
}

template std::unique_ptr<Integrator<2>> make_leapfrog(const IntegratorParams&, RateSource<2>&);
template std::unique_ptr<Integrator<3>> make_leapfrog(const IntegratorParams&, RateSource<3>&);

}  // namespace sphdisk
