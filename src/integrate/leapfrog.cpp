// Kick-drift-kick leapfrog (physics.md sec. 3). Viscous accelerations depend on velocity, so the
// rates at the end of the drift are evaluated with the predicted velocity v_half + a_old dt/2 and
// then used for the closing kick (as in Phantom).
#include <algorithm>

#include "integrate/integrator.hpp"

namespace sphdisk {

template <int D>
class Leapfrog final : public Integrator<D> {
 public:
  Leapfrog(const IntegratorParams& params, RateEvaluator<D>& rates) : params_(params), rates_(rates) {}

  void start(Particles<D>& p) override { rates_.evaluate(p); }

  double step(Particles<D>& p, double dt_cap) override {
    const double dt =
        std::min({dt_cap, params_.dt_max, rates_.global_min(explicit_timestep(p, rates_.physics(), params_.factors))});
    const double half = 0.5 * dt;
    const bool energy = rates_.physics().evolve_energy;
    const std::size_t n = p.size();
    v_half_.resize(n);
    u_half_.resize(n);
    {
    ScopedPhase timer(rates_.timers(), "integration");
    par::for_each(n, [&](std::size_t i) {
      v_half_[i] = p.vel[i] + p.acc[i] * half;          // kick
      p.pos[i] += v_half_[i] * dt;                      // drift
      p.vel[i] = v_half_[i] + p.acc[i] * half;          // predicted velocity for the rates
      if (energy) {
        u_half_[i] = p.u[i] + p.du_dt[i] * half;
        p.u[i] = u_half_[i] + p.du_dt[i] * half;
      }
    }, "integration");
    }
    rates_.evaluate(p);
    ScopedPhase timer(rates_.timers(), "integration");
    par::for_each(n, [&](std::size_t i) {
      p.vel[i] = v_half_[i] + p.acc[i] * half;          // kick
      if (energy) p.u[i] = u_half_[i] + p.du_dt[i] * half;
    }, "integration");
    return dt;
  }

 private:
  IntegratorParams params_;
  RateEvaluator<D>& rates_;
  std::vector<Vec<D>> v_half_;
  std::vector<double> u_half_;
};

template <int D>
std::unique_ptr<Integrator<D>> make_leapfrog(const IntegratorParams& params, RateEvaluator<D>& rates) {
  return std::make_unique<Leapfrog<D>>(params, rates);
}

template std::unique_ptr<Integrator<2>> make_leapfrog(const IntegratorParams&, RateEvaluator<2>&);
template std::unique_ptr<Integrator<3>> make_leapfrog(const IntegratorParams&, RateEvaluator<3>&);

}  // namespace sphdisk
