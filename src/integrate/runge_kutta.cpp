// Embedded explicit Runge-Kutta with error control (Dormand-Prince 5(4)): the paper's integrator
// with an "error tolerance" (P98 sec. 5.3). The state is y = (x, v, u) with dy/dt = (v, a, du/dt). Each stage is a
// full rate evaluation. The error estimate is the difference between the two embedded solutions,
// measured relative to each particle's |x| and |v| (relative tolerance, as miluphcuda uses on
// positions); steps with error > tolerance are rejected and retried. The higher-order solution is
// kept (local extrapolation), and the last stage is the first of the next step (FSAL).
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/named_choice.hpp"
#include "integrate/integrator.hpp"
#include "physics/viscosity_switch.hpp"

namespace sphdisk {

namespace {

struct Tableau {
  int stages;
  int error_order;  // order of the lower embedded solution + 1: exponent of the step-size update
  std::vector<double> c;
  std::vector<std::vector<double>> a;  // a[s][l], l < s
  std::vector<double> b_high, b_low;
};

// Dormand & Prince (1980), 5th order with 4th-order error estimate, FSAL.
Tableau dormand_prince() {
  return {7, 5, {0, 0.2, 0.3, 0.8, 8.0 / 9, 1.0, 1.0},
          {{},
           {0.2},
           {3.0 / 40, 9.0 / 40},
           {44.0 / 45, -56.0 / 15, 32.0 / 9},
           {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
           {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
           {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}},
          {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84, 0},
          {5179.0 / 57600, 0, 7571.0 / 16695, 393.0 / 640, -92097.0 / 339200, 187.0 / 2100, 1.0 / 40}};
}

template <int D>
struct StageRates {
  std::vector<Vec<D>> dx, dv;  // dx/dt = v, dv/dt = a
  std::vector<double> du;
};

}  // namespace

template <int D>
class EmbeddedRungeKutta final : public Integrator<D> {
 public:
  EmbeddedRungeKutta(const IntegratorParams& params, RateSource<D>& rates, Tableau tab)
      : params_(params), rates_(rates), tab_(std::move(tab)), k_(static_cast<std::size_t>(tab_.stages)) {}

  void start(Particles<D>& p) override { rates_.evaluate(p); }

  double step(Particles<D>& p, double dt_cap) override {
    const PhysicsParams& phys = rates_.physics();
    const double dt_stable = std::min(
        stability_timestep(rates_.global_min(smallest_smoothing_length(p)), rates_.global_max(largest_viscosity(p, phys)),
                           rates_.global_max(largest_sound_speed(p, phys)), phys, params_.factors),
        params_.dt_max);
    if (dt_next_ <= 0) dt_next_ = rates_.global_min(explicit_timestep(p, phys, params_.factors));
    save_initial_state(p);
    for (;;) {
      const double dt = std::min({dt_next_, dt_stable, dt_cap});
      const double err = attempt(p, dt);
      const double grow = err > 0 ? 0.9 * std::pow(err, -1.0 / tab_.error_order) : 5.0;
      if (err <= 1.0) {
        if (phys.artificial_viscosity() && phys.av_switch)
          par::for_each(p.size(), [&](std::size_t i) { advance_viscosity_switch(p, i, dt, phys); }, "integration");
        // A step shortened only to hit dt_cap (an output time) must not shrink the next one.
        const double proposed = dt * std::clamp(grow, 0.2, 5.0);
        dt_next_ = dt < dt_next_ ? std::max(dt_next_, proposed) : proposed;
        return dt;
      }
      ++rejected_;
      dt_next_ = dt * std::clamp(grow, 0.1, 0.9);
      restore_initial_state(p);
    }
  }

  std::size_t rejected_steps() const override { return rejected_; }
  std::size_t bytes() const override {
    std::size_t b = (x0_.capacity() + v0_.capacity() + a0_.capacity()) * sizeof(Vec<D>) +
                    (u0_.capacity() + du0_.capacity()) * sizeof(double);
    for (const auto& k : k_) b += (k.dx.capacity() + k.dv.capacity()) * sizeof(Vec<D>) + k.du.capacity() * sizeof(double);
    return b;
  }
  std::vector<double> state() const override { return {dt_next_, static_cast<double>(rejected_)}; }
  void set_state(const std::vector<double>& s) override {
    if (s.size() != 2) throw UserError("checkpoint: the Runge-Kutta integrator state must hold 2 values");
    dt_next_ = s[0];
    rejected_ = static_cast<std::size_t>(s[1]);
  }

 private:
  void save_initial_state(const Particles<D>& p) {
    x0_ = p.pos;
    v0_ = p.vel;
    u0_ = p.u;
    a0_ = p.acc;
    du0_ = p.du_dt;
  }
  void restore_initial_state(Particles<D>& p) {
    p.pos = x0_;
    p.vel = v0_;
    p.u = u0_;
    p.acc = a0_;
    p.du_dt = du0_;
  }
  void store_stage(const Particles<D>& p, std::size_t s) {
    k_[s].dx = p.vel;
    k_[s].dv = p.acc;
    k_[s].du = p.du_dt;
  }

  // Sets p to y0 + dt * sum_l w[l] k_l.
  void combine(Particles<D>& p, double dt, const std::vector<double>& w, std::size_t nstages) {
    const bool energy = rates_.physics().evolve_energy;
    ScopedPhase timer(rates_.timers(), "integration");
    par::for_each(p.size(), [&](std::size_t i) {
      Vec<D> x = x0_[i], v = v0_[i];
      double u = energy ? u0_[i] : 0.0;  // (no internal energy without an energy equation)
      for (std::size_t l = 0; l < nstages; ++l) {
        if (w[l] == 0.0) continue;
        x += k_[l].dx[i] * (dt * w[l]);
        v += k_[l].dv[i] * (dt * w[l]);
        if (energy) u += k_[l].du[i] * (dt * w[l]);
      }
      p.pos[i] = x;
      p.vel[i] = v;
      if (energy) p.u[i] = u;
    }, "integration");
  }

  // One trial step; returns the error norm in units of the tolerance and leaves p at the
  // higher-order solution with its rates evaluated.
  double attempt(Particles<D>& p, double dt) {
    const auto S = static_cast<std::size_t>(tab_.stages);
    store_stage(p, 0);  // FSAL: the rates of y0 are already in p
    for (std::size_t s = 1; s < S; ++s) {
      combine(p, dt, tab_.a[s], s);
      rates_.evaluate(p);
      store_stage(p, s);
    }
    // Last stage of an FSAL tableau is evaluated at the high-order solution: p holds it already.
    std::vector<double> diff(S);
    for (std::size_t l = 0; l < S; ++l) diff[l] = tab_.b_high[l] - tab_.b_low[l];
    const double tol = params_.tolerance;
    const bool energy = rates_.physics().evolve_energy;
    return rates_.global_max(par::reduce(
        p.size(), 0.0,
        [&](std::size_t i) {
          Vec<D> ex, ev;
          double eu = 0;
          for (std::size_t l = 0; l < S; ++l) {
            ex += k_[l].dx[i] * (dt * diff[l]);
            ev += k_[l].dv[i] * (dt * diff[l]);
            if (energy) eu += k_[l].du[i] * (dt * diff[l]);
          }
          double e = std::max(norm(ex) / (tol * norm(p.pos[i]) + 1e-300), norm(ev) / (tol * norm(p.vel[i]) + 1e-300));
          if (energy) e = std::max(e, std::abs(eu) / (tol * std::abs(p.u[i]) + 1e-300));
          return e;
        },
        [](double a, double b) { return std::max(a, b); }));
  }

  IntegratorParams params_;
  RateSource<D>& rates_;
  Tableau tab_;
  std::vector<StageRates<D>> k_;
  std::vector<Vec<D>> x0_, v0_, a0_;
  std::vector<double> u0_, du0_;
  double dt_next_ = 0;
  std::size_t rejected_ = 0;
};

template <int D>
std::unique_ptr<Integrator<D>> make_leapfrog(const IntegratorParams& params, RateSource<D>& rates);
template <int D>
std::unique_ptr<Integrator<D>> make_block_leapfrog(const IntegratorParams& params, RateSource<D>& rates);

Scheme scheme_from_name(const std::string& name) {
  static constexpr NamedChoice<Scheme> kNames[] = {{"block", Scheme::Block}, {"leapfrog", Scheme::Leapfrog},
                                                   {"respa", Scheme::Respa}, {"rk45", Scheme::RK45}};
  return choice_from_name<Scheme>("integrator.scheme", name, kNames);
}

ViscousUpdate viscous_update_from_name(const std::string& name) {
  static constexpr NamedChoice<ViscousUpdate> kNames[] = {{"explicit", ViscousUpdate::Explicit},
                                                          {"super_steps", ViscousUpdate::SuperSteps}};
  return choice_from_name<ViscousUpdate>("integrator.viscous_update", name, kNames);
}

template <int D>
std::unique_ptr<Integrator<D>> make_integrator(const IntegratorParams& params, RateSource<D>& rates) {
  switch (params.scheme) {
    case Scheme::RK45: return std::make_unique<EmbeddedRungeKutta<D>>(params, rates, dormand_prince());
    case Scheme::Block: return make_block_leapfrog<D>(params, rates);
    case Scheme::Leapfrog:
    case Scheme::Respa: break;
  }
  return make_leapfrog<D>(params, rates);
}

template std::unique_ptr<Integrator<2>> make_integrator(const IntegratorParams&, RateSource<2>&);
template std::unique_ptr<Integrator<3>> make_integrator(const IntegratorParams&, RateSource<3>&);

}  // namespace sphdisk
