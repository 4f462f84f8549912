// Individual block timesteps (power-of-two bins on an integer time line, as in GADGET-4, SWIFT and
// Phantom) for the hydrodynamic forces, with the point mass's gravity substepped per particle in
// between (the r-RESPA split of leapfrog.cpp).
//
// One call of step() is one block cycle of length Delta, at whose ends every particle is
// synchronised (so checkpoints, outputs and rebalancing see the same state as with one global step):
//   - Delta = min(dt_cap, dt_max, largest hydro step, smallest hydro step x 2^kMaxBins); the cycle
//     has 2^kMaxBins ticks; particle i steps 2^k ticks, the largest power of two with
//     2^k ticks <= its hydro step (particle_timestep on the SPH acceleration, timestep.hpp).
//   - At the start of its step a particle gets the opening half kick with its acceleration; all
//     particles move in the point mass's field between the ticks where some step ends; particles
//     whose step ends there (the active ones) get new rates and the closing half kick, then a new
//     step: the largest one allowed by its criteria whose ticks divide the current tick (so steps
//     stay nested and all end together at the end of the cycle).
//   - Inactive particles take part in the active ones' sums with their velocities predicted to the
//     current time (v + a (t - t_mid)), their drifted positions, the h and rho of their last
//     evaluation (as in Phantom), and the stress of their last evaluation turned with them about
//     the central mass: in a disc the stress is nearly steady in the co-rotating (r, phi) frame, so
//     its Cartesian components turn at the orbital frequency; left unturned, a stress half a step
//     old would be off by Omega dt / 2 radians (the first-order error this removes was measured:
//     tests/unit/integrate/test_integrators.cpp).
// The particles are kept grouped by step length, shortest first (at the start of a cycle by a
// stable sort, so each bin keeps the cell order of the last reorder; inside it by moving only the
// particles outside their bin's range). A step of 2^k ticks starts at a multiple of
// 2^k, so the steps ending at tick t are exactly those of at most the largest power of two dividing
// t: the active particles are always a prefix, and the rates are computed for the first n_active
// particles (RateSource::evaluate(p, active)). Only the active prefix gets new lengths, none
// longer than that power of two (they must divide t) while every inactive one is longer, so
// regrouping the prefix alone keeps the whole order: the integrator's own work per evaluation,
// beyond the drift, scales with the active particles, not with all of them. Every choice depends
// only on a particle's own state and on global minima and maxima, so results do not depend on
// thread or rank count. With every particle in one bin this is exactly the respa scheme.
// Each particle's step (start and length) and its velocity and energy after the opening kick are
// particle fields (kStepState, core/particles.hpp), so they move with it; between two ticks they,
// the cycle's length and the ticks done are all a checkpoint needs to continue the cycle
// (inside_step, step_state, resume_inside_step: integrator.hpp).
//
// With super-steps (ViscousUpdate::SuperSteps) a particle's step has no opening kick: it moves with
// its velocity in the point mass's field, and at the step's end its hydrodynamic rates advance its
// velocity (and energy) over the whole step at the positions reached, by forward-Euler substeps or a
// Runge-Kutta-Legendre step (super_steps.hpp), with as few evaluations as its own step needs in
// explicit viscous limits (super_step_rates). The steps are then bounded by the orbital and force
// criteria and by max_stages, not by h^2 / nu. v_kick holds the velocity the particle moves with,
// acc the mean hydrodynamic acceleration of its last step (what neighbours predict its velocity with).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "core/error.hpp"
#include "integrate/integrator.hpp"
#include "integrate/orbit_drift.hpp"
#include "integrate/super_steps.hpp"
#include "physics/viscosity_switch.hpp"

namespace sphdisk {

namespace {

constexpr int kMaxBins = 20;  // steps down to Delta / 2^20
constexpr std::uint64_t kTicks = std::uint64_t{1} << kMaxBins;
static_assert(kMaxBins < 32, "a step's start and length fit in 32 bits each (Particles::step_ticks)");
constexpr std::size_t kDriftBlock = 1024;  // particles per work unit of the drift
// Super-steps: the step, in h_i^2 / nu, that one forward-Euler update of the viscous rates takes
// stably, with a factor 2 kept from the measured limit 2 / |lambda_max|. The largest eigenvalue
// modulus of those rates on the ring is 0.68-0.94 nu / h_min^2 with the consistent divergence (any
// gradient correction or pair density) and 1.84-1.95 with the conservative one at 10k-100k particles
// (bench/viscous_spectrum.cpp; docs/validation.md, "The viscous rates' spectrum"), so forward Euler
// is stable to 2.1 and 1.03 h_min^2 / nu.
double explicit_viscous_limit(const PhysicsParams& phys) {
  return phys.viscous_force == ViscousForce::Consistent ? 1.0 : 0.5;
}

// The largest power-of-two number of ticks whose duration is within dt and which divides `tick`.
std::uint64_t step_ticks(double dt, double tick_duration, std::uint64_t tick) {
  std::uint64_t s = kTicks;
  while (s > 1 && (static_cast<double>(s) * tick_duration > dt || tick % s != 0)) s >>= 1;
  return s;
}

}  // namespace

template <int D>
class BlockLeapfrog final : public Integrator<D> {
 public:
  BlockLeapfrog(const IntegratorParams& params, RateSource<D>& rates)
      : params_(params), rates_(rates), super_steps_(params.viscous_update == ViscousUpdate::SuperSteps),
        step_factors_(params.factors) {
    rates_.include_gravity(false);
    if (super_steps_) step_factors_.viscous = explicit_viscous_limit(rates_.physics()) * rkl2_reach(params.max_stages);
  }

  void start(Particles<D>& p) override { rates_.evaluate(p); }
  bool needs_rate_state() const override { return true; }

  // Inside a cycle (between its ticks, or resumed into one and not yet continued) the particles
  // carry their steps (kStepState fields); the cycle's length and the ticks done are the rest.
  bool inside_step() const override { return now_ > 0; }
  bool keeps_step_state() const override { return true; }
  // (The third value says whether the steps have opening kicks: a cycle cannot go on with the other
  // update. Checkpoints written without it come from explicit steps.)
  std::vector<double> step_state() const override {
    return {cycle_, static_cast<double>(now_), super_steps_ ? 1.0 : 0.0};
  }
  void resume_inside_step(const std::vector<double>& s) override {
    if (s.size() == 3 && s[2] != (super_steps_ ? 1.0 : 0.0))
      throw UserError(std::string("the checkpoint was written inside a block cycle with integrator.viscous_update = ") +
                      (super_steps_ ? "\"explicit\"" : "\"super_steps\"") + ": resume it with that setting");
    if ((s.size() != 2 && s.size() != 3) || !(s[0] > 0) || !std::isfinite(s[0]) || !(s[1] >= 1) ||
        !(s[1] < static_cast<double>(kTicks)) || s[1] != std::floor(s[1]))
      throw UserError("the checkpoint's block-cycle state is not valid (cycle length and ticks done); resume from "
                      "another checkpoint or start the run again");
    cycle_ = s[0];
    now_ = static_cast<std::uint64_t>(s[1]);
  }

  double step(Particles<D>& p, double dt_cap) override {
    const PhysicsParams& phys = rates_.physics();
    const TimestepFactors& f = params_.factors;
    const std::size_t n = p.size();
    const bool energy = phys.evolve_energy;
    if (now_ == 0) {
      // Each particle's timestep is needed only to choose its step length: not kept (8 bytes per
      // particle less at the run's peak memory).
      std::vector<double> dt(n);
      par::for_each(n, [&](std::size_t i) { dt[i] = particle_timestep(p, i, phys, step_factors_); }, "integration");
      const double smallest = rates_.global_min(smallest_timestep(n, [&](std::size_t i) { return dt[i]; }));
      const double largest = rates_.global_max(
          par::reduce(n, 0.0, [&](std::size_t i) { return dt[i]; }, [](double a, double b) { return std::max(a, b); }));
      cycle_ = std::min({dt_cap, params_.dt_max, largest, smallest * static_cast<double>(kTicks)});
      const double tick = cycle_ / static_cast<double>(kTicks);
      ScopedPhase timer(rates_.timers(), "integration");
      par::for_each(n, [&](std::size_t i) {
        set_step(p, i, 0, step_ticks(dt[i], tick, 0));
        open_step(p, i, tick, energy);
      }, "integration");
    }
    {
      // (Resumed inside a cycle, the particles may come in another order: a checkpoint of several
      // ranks is read in ID order.)
      ScopedPhase timer(rates_.timers(), "integration");
      sort_by_length(p, n);
    }
    const double tick = cycle_ / static_cast<double>(kTicks);
    for (std::uint64_t now = now_; now < kTicks;) {
      const std::uint64_t next = next_tick(p, n);
      const double dt = static_cast<double>(next - now) * tick;
      std::size_t active = 0;
      {
        ScopedPhase timer(rates_.timers(), "integration");
        par::for_each((n + kDriftBlock - 1) / kDriftBlock, [&](std::size_t b) {
          const std::size_t i0 = b * kDriftBlock, i1 = std::min(n, i0 + kDriftBlock);
          // Moved in the point mass's field, stresses turned with the orbit (active particles get
          // theirs anew): orbit_drift.hpp.
          drift_and_turn(p.pos.data() + i0, p.v_kick.data() + i0, p.stress.data() + i0, i1 - i0, dt, phys.gm, f.substep);
          for (std::size_t i = i0; i < i1; ++i) {
            // predicted to `next`: t - t_mid = (next - start - length / 2) ticks
            // (with super-steps from the step's start: no opening kick)
            const double ahead = (static_cast<double>(next - start_of(p, i)) -
                                  (super_steps_ ? 0.0 : 0.5 * static_cast<double>(length_of(p, i)))) * tick;
            p.vel[i] = p.v_kick[i] + p.acc[i] * ahead;
            if (energy) p.u[i] = p.u_kick[i] + p.du_dt[i] * ahead;
          }
        }, "integration", 1);
        active = active_prefix(p, next);
      }
      if (super_steps_) {
        super_step_rates(p, active, tick, energy);
      } else {
        rates_.evaluate(p, active);
        ScopedPhase timer(rates_.timers(), "integration");
        const bool switching = phys.artificial_viscosity() && phys.av_switch;
        par::for_each(active, [&](std::size_t i) {
          const double length = static_cast<double>(length_of(p, i)) * tick, half = 0.5 * length;
          p.vel[i] = p.v_kick[i] + p.acc[i] * half;  // closing kick
          if (energy) p.u[i] = p.u_kick[i] + p.du_dt[i] * half;
          if (switching) advance_viscosity_switch(p, i, length, phys);
        }, "integration");
      }
      if (next != kTicks) {
        ScopedPhase timer(rates_.timers(), "integration");
        par::for_each(active, [&](std::size_t i) {
          set_step(p, i, next, step_ticks(particle_timestep(p, i, phys, step_factors_), tick, next));
          open_step(p, i, tick, energy);
        }, "integration");
        group_by_length(p, active);
      }
      now = next;
      now_ = now < kTicks ? now : 0;
      if (now < kTicks) this->substep_done(static_cast<double>(now) * tick, cycle_);
    }
    return cycle_;
  }

  std::size_t bytes() const override {
    return (order_.capacity() + holes_.capacity()) * sizeof(std::uint32_t) + velocities_.bytes() + energies_.bytes();
  }

 private:
  // A particle's step: its start (high 32 bits of step_ticks) and length (low 32 bits), in ticks.
  static std::uint64_t start_of(const Particles<D>& p, std::size_t i) { return p.step_ticks[i] >> 32; }
  static std::uint64_t length_of(const Particles<D>& p, std::size_t i) { return p.step_ticks[i] & 0xFFFFFFFFu; }
  static std::uint64_t end_of(const Particles<D>& p, std::size_t i) { return start_of(p, i) + length_of(p, i); }
  static void set_step(Particles<D>& p, std::size_t i, std::uint64_t start, std::uint64_t length) {
    p.step_ticks[i] = start << 32 | length;
  }

  void open_step(Particles<D>& p, std::size_t i, double tick, bool energy) {
    const double half = super_steps_ ? 0.0 : 0.5 * static_cast<double>(length_of(p, i)) * tick;
    p.v_kick[i] = p.vel[i] + p.acc[i] * half;
    if (energy) p.u_kick[i] = p.u[i] + p.du_dt[i] * half;
  }

  std::uint64_t next_tick(const Particles<D>& p, std::size_t n) const {
    const double mine = smallest_timestep(n, [&](std::size_t i) { return static_cast<double>(end_of(p, i)); });
    return static_cast<std::uint64_t>(rates_.global_min(mine));  // ticks < 2^53: exact as doubles
  }

  // The number of particles whose step ends at `tick`: a prefix (see the top of this file; checked,
  // since a particle left out would silently miss its kick; a parallel count).
  std::size_t active_prefix(const Particles<D>& p, std::uint64_t tick) const {
    const std::size_t n = p.size();
    std::size_t active = 0;
    while (active < n && end_of(p, active) == tick) ++active;
    const std::size_t strays =
        par::sum<std::size_t>(n - active, [&](std::size_t k) { return std::size_t{end_of(p, active + k) == tick}; });
    if (strays > 0) throw std::logic_error("block timesteps: the active particles are not a prefix");
    return active;
  }

  // Whether the first `count` particles are grouped by step length, shortest first.
  static bool grouped(const Particles<D>& p, std::size_t count) {
    for (std::size_t i = 1; i < count; ++i)
      if (length_of(p, i) < length_of(p, i - 1)) return false;
    return true;
  }

  // Stable counting sort of the first `count` particles by step length, shortest first; nothing is
  // moved when they are in order already. At the start of a cycle (just after the particles were
  // put in cell order), so that each bin keeps that order.
  void sort_by_length(Particles<D>& p, std::size_t count) {
    sort_prefix(p, count, kMaxBins + 1, [&p](std::size_t i) { return bin(p, i); });
  }

  // Stable counting sort of the first `count` particles by key(i) < buckets; nothing is moved when
  // they are in order already. Whether any moved (then particle k is the one that was order_[k]).
  template <class Key>
  bool sort_prefix(Particles<D>& p, std::size_t count, std::size_t buckets, Key key) {
    bool sorted = true;
    for (std::size_t i = 1; i < count && sorted; ++i) sorted = key(i - 1) <= key(i);
    if (sorted) return false;
    std::vector<std::size_t> next(buckets + 1, 0);
    for (std::size_t i = 0; i < count; ++i) ++next[key(i) + 1];
    for (std::size_t b = 1; b <= buckets; ++b) next[b] += next[b - 1];
    order_.resize(count);
    for (std::size_t i = 0; i < count; ++i) order_[next[key(i)]++] = static_cast<std::uint32_t>(i);
    p.for_each_field([this](const FieldInfo&, auto& v) { par::permute_prefix(v, order_, "integration"); });
    return true;
  }

  // The same grouping inside a cycle, moving only the particles outside their bin's range: the k-th
  // of those that belong to bin b (in memory order) takes the k-th place in b's range held by a
  // particle of another bin. A stable sort would move nearly all of the prefix (a particle that
  // changes bin shifts every one between its old and new place), where most particles already lie
  // in their bin's range. Memory order changes no particle's
  // values (the pair sums follow cell order), only the round-off of sums over all particles such
  // as the diagnostics' energy, and it is the same for any thread count.
  void group_by_length(Particles<D>& p, std::size_t count) {
    if (grouped(p, count)) return;
    const std::array<std::size_t, kMaxBins + 2> first = bin_starts(p, count);
    // Out-of-range particles (sources) and the places they leave (holes), each counted by bin.
    std::array<std::size_t, kMaxBins + 2> source_at{}, hole_at{};
    std::size_t region = 0, misplaced = 0;
    for (std::size_t k = 0; k < count; ++k) {
      while (k >= first[region + 1]) ++region;
      const std::size_t b = bin(p, k);
      if (b == region) continue;
      ++source_at[b + 1];
      ++hole_at[region + 1];
      ++misplaced;
    }
    for (std::size_t b = 1; b < source_at.size(); ++b) {
      source_at[b] += source_at[b - 1];
      hole_at[b] += hole_at[b - 1];
    }
    order_.resize(misplaced);
    holes_.resize(misplaced);
    region = 0;
    for (std::size_t k = 0; k < count; ++k) {
      while (k >= first[region + 1]) ++region;
      const std::size_t b = bin(p, k);
      if (b == region) continue;
      order_[source_at[b]++] = static_cast<std::uint32_t>(k);
      holes_[hole_at[region]++] = static_cast<std::uint32_t>(k);
    }
    // (Every field in turn, in parallel inside: a serial Particles::gather was most of this
    // integrator's own time.)
    p.for_each_field([this](const FieldInfo&, auto& v) { par::move_values(v, order_, holes_, "integration"); });
  }

  // The active particles' hydrodynamic rates over their steps just ended, from the velocity (and
  // energy) they moved with, at the positions reached: each takes as few evaluations as its step
  // needs in explicit limits (super_steps.hpp), so the particles are ordered by that count, most
  // first, and each evaluation after the first covers only those that still need it. acc then holds
  // the mean acceleration over the step.
  void super_step_rates(Particles<D>& p, std::size_t active, double tick, bool energy) {
    const PhysicsParams& phys = rates_.physics();
    const double limit = explicit_viscous_limit(phys);
    const auto tau = [&](std::size_t i) { return static_cast<double>(length_of(p, i)) * tick; };
    // (from the h just solved for, which the later evaluations keep: RateEvaluator::evaluate_again;
    // recomputed where asked for, not stored, as the stages keep positions, h and step lengths)
    const auto plan_at = [&](std::size_t i) {
      const double nu = largest_viscosity_at(phys, p.pos[i]);
      return super_step_plan(nu > 0 ? tau(i) * nu / (limit * p.h[i] * p.h[i]) : 0.0);
    };
    par::for_each(active, [&](std::size_t i) {
      p.vel[i] = p.v_kick[i];
      if (energy) p.u[i] = p.u_kick[i];
    }, "integration");
    rates_.evaluate(p, active);
    int most = 1;
    bool moved = false;
    {
      ScopedPhase timer(rates_.timers(), "integration");
      const double mine = par::reduce(active, 1.0, [&](std::size_t i) { return double(plan_at(i).evaluations); },
                                      [](double a, double b) { return std::max(a, b); });
      most = static_cast<int>(rates_.global_max(mine));
      if (most > 1) moved = sort_prefix(p, active, static_cast<std::size_t>(most), [&](std::size_t i) {
        return static_cast<std::size_t>(most - plan_at(i).evaluations);
      });
    }
    // (The first stage learns how the sort above renumbered the particles.)
    const auto rate = [&](std::size_t m) {
      rates_.evaluate_again(p, m, moved ? std::span<const std::uint32_t>(order_) : std::span<const std::uint32_t>());
      moved = false;
    };
    const auto each = [](std::size_t m, auto&& f) { par::for_each(m, f, "integration"); };
    velocities_.bind(p.vel, p.acc, p.v_kick, active);  // (vel was set to v_kick above: Y_0)
    if (energy) {
      energies_.bind(p.u, p.du_dt, p.u_kick, active);
      super_step(active, most, plan_at, tau, rate, each, velocities_, energies_);
    } else {
      super_step(active, most, plan_at, tau, rate, each, velocities_);
    }
    ScopedPhase timer(rates_.timers(), "integration");
    par::for_each(active, [&](std::size_t i) {
      const double t = tau(i);
      p.acc[i] = (p.vel[i] - p.v_kick[i]) * (1.0 / t);
      p.v_kick[i] = p.vel[i];
      if (energy) {
        p.du_dt[i] = (p.u[i] - p.u_kick[i]) / t;
        p.u_kick[i] = p.u[i];
      }
    }, "integration");
  }

  static std::size_t bin(const Particles<D>& p, std::size_t i) {
    return static_cast<std::size_t>(std::countr_zero(length_of(p, i)));
  }

  // first[k]: where the particles of 2^k ticks start among the first `count` once grouped by length.
  static std::array<std::size_t, kMaxBins + 2> bin_starts(const Particles<D>& p, std::size_t count) {
    std::array<std::size_t, kMaxBins + 2> first{};
    for (std::size_t i = 0; i < count; ++i) ++first[bin(p, i) + 1];
    for (std::size_t k = 1; k < first.size(); ++k) first[k] += first[k - 1];
    return first;
  }

  IntegratorParams params_;
  RateSource<D>& rates_;
  bool super_steps_;
  TimestepFactors step_factors_;  // the steps' criteria (with super-steps, a viscous limit max_stages reach)
  Rkl2Part<Vec<D>> velocities_;
  Rkl2Part<double> energies_;
  double cycle_ = 0;       // the length of the cycle in progress
  std::uint64_t now_ = 0;  // its ticks done, while inside it (0 between cycles)
  std::vector<std::uint32_t> order_, holes_;
};

template <int D>
std::unique_ptr<Integrator<D>> make_block_leapfrog(const IntegratorParams& params, RateSource<D>& rates) {
  return std::make_unique<BlockLeapfrog<D>>(params, rates);
}

template std::unique_ptr<Integrator<2>> make_block_leapfrog(const IntegratorParams&, RateSource<2>&);
template std::unique_ptr<Integrator<3>> make_block_leapfrog(const IntegratorParams&, RateSource<3>&);

}  // namespace sphdisk
