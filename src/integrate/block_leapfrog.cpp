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
//     tests/unit/test_integrators.cpp).
// The particles are kept grouped by step length, shortest first (at the start of a cycle by a
// stable sort, so each bin keeps the cell order of the last reorder; inside it by moving only the
// particles outside their bin's range). A step of 2^k ticks starts at a multiple of
// 2^k, so the steps ending at tick t are exactly those of at most the largest power of two dividing
// t: the active particles are always a prefix, and the rates are computed for the first n_active
// particles (RateEvaluator::evaluate(p, active)). Only the active prefix gets new lengths, none
// longer than that power of two (they must divide t) while every inactive one is longer, so
// regrouping the prefix alone keeps the whole order: the integrator's own work per evaluation,
// beyond the drift, scales with the active particles, not with all of them. Every choice depends
// only on a particle's own state and on global minima and maxima, so results do not depend on
// thread or rank count. With every particle in one bin this is exactly the respa scheme.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "integrate/integrator.hpp"
#include "integrate/orbit_drift.hpp"

namespace sphdisk {

namespace {

constexpr int kMaxBins = 20;  // steps down to Delta / 2^20
constexpr std::uint64_t kTicks = std::uint64_t{1} << kMaxBins;
using Ticks = std::uint32_t;  // a step's start and length (4 bytes per particle each, not 8)
static_assert(kMaxBins < 32, "a cycle's ticks fit in Ticks");
constexpr std::size_t kDriftBlock = 1024;  // particles per work unit of the drift

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
  BlockLeapfrog(const IntegratorParams& params, RateEvaluator<D>& rates) : params_(params), rates_(rates) {
    rates_.include_gravity(false);
  }

  void start(Particles<D>& p) override { rates_.evaluate(p); }
  bool needs_rate_state() const override { return true; }

  double step(Particles<D>& p, double dt_cap) override {
    const PhysicsParams& phys = rates_.physics();
    const TimestepFactors& f = params_.factors;
    const std::size_t n = p.size();
    const bool energy = phys.evolve_energy;
    double cycle = 0, tick = 0;
    {
      // Each particle's timestep is needed only to choose its step length: not kept (8 bytes per
      // particle less at the run's peak memory).
      std::vector<double> dt(n);
      par::for_each(n, [&](std::size_t i) { dt[i] = particle_timestep(p, i, phys, f); }, "integration");
      const double smallest = rates_.global_min(smallest_timestep(n, [&](std::size_t i) { return dt[i]; }));
      const double largest = rates_.global_max(
          par::reduce(n, 0.0, [&](std::size_t i) { return dt[i]; }, [](double a, double b) { return std::max(a, b); }));
      cycle = std::min({dt_cap, params_.dt_max, largest, smallest * static_cast<double>(kTicks)});
      tick = cycle / static_cast<double>(kTicks);

      start_.assign(n, 0);
      length_.resize(n);
      v_kick_.resize(n);
      u_half_.resize(energy ? n : 0);  // u is not integrated without an energy equation
      ScopedPhase timer(rates_.timers(), "integration");
      par::for_each(n, [&](std::size_t i) {
        length_[i] = static_cast<Ticks>(step_ticks(dt[i], tick, 0));
        open_step(p, i, tick, energy);
      }, "integration");
    }
    {
      ScopedPhase timer(rates_.timers(), "integration");
      sort_by_length(p, n);
    }
    for (std::uint64_t now = 0; now < kTicks;) {
      const std::uint64_t next = next_tick(n);
      const double dt = static_cast<double>(next - now) * tick;
      std::size_t active = 0;
      {
        ScopedPhase timer(rates_.timers(), "integration");
        par::for_each((n + kDriftBlock - 1) / kDriftBlock, [&](std::size_t b) {
          const std::size_t i0 = b * kDriftBlock, i1 = std::min(n, i0 + kDriftBlock);
          // Moved in the point mass's field, stresses turned with the orbit (active particles get
          // theirs anew): orbit_drift.hpp.
          drift_and_turn(p.pos.data() + i0, v_kick_.data() + i0, p.stress.data() + i0, i1 - i0, dt, phys.gm, f.substep);
          for (std::size_t i = i0; i < i1; ++i) {
            // predicted to `next`: t - t_mid = (next - start - length / 2) ticks
            const double ahead = (static_cast<double>(next - start_[i]) - 0.5 * static_cast<double>(length_[i])) * tick;
            p.vel[i] = v_kick_[i] + p.acc[i] * ahead;
            if (energy) p.u[i] = u_half_[i] + p.du_dt[i] * ahead;
          }
        }, "integration", 1);
        active = active_prefix(next);
      }
      rates_.evaluate(p, active);
      {
        ScopedPhase timer(rates_.timers(), "integration");
        par::for_each(active, [&](std::size_t i) {
          const double half = 0.5 * static_cast<double>(length_[i]) * tick;
          p.vel[i] = v_kick_[i] + p.acc[i] * half;  // closing kick
          if (energy) p.u[i] = u_half_[i] + p.du_dt[i] * half;
          if (next == kTicks) return;  // synchronised at the end of the cycle: the next cycle opens
          start_[i] = static_cast<Ticks>(next);
          length_[i] = static_cast<Ticks>(step_ticks(particle_timestep(p, i, phys, f), tick, next));
          open_step(p, i, tick, energy);
        }, "integration");
        if (next != kTicks) group_by_length(p, active);
      }
      now = next;
      if (now < kTicks) this->substep_done(static_cast<double>(now) * tick, cycle);
    }
    return cycle;
  }

  std::size_t bytes() const override {
    return u_half_.capacity() * sizeof(double) + (start_.capacity() + length_.capacity()) * sizeof(Ticks) +
           v_kick_.capacity() * sizeof(Vec<D>) + (order_.capacity() + holes_.capacity()) * sizeof(std::uint32_t);
  }

 private:
  void open_step(const Particles<D>& p, std::size_t i, double tick, bool energy) {
    const double half = 0.5 * static_cast<double>(length_[i]) * tick;
    v_kick_[i] = p.vel[i] + p.acc[i] * half;
    if (energy) u_half_[i] = p.u[i] + p.du_dt[i] * half;
  }

  std::uint64_t next_tick(std::size_t n) const {
    const double mine = smallest_timestep(n, [&](std::size_t i) { return static_cast<double>(start_[i] + length_[i]); });
    return static_cast<std::uint64_t>(rates_.global_min(mine));  // ticks < 2^53: exact as doubles
  }

  // The number of particles whose step ends at `tick`: a prefix (see the top of this file; checked,
  // since a particle left out would silently miss its kick; a parallel count over two arrays).
  std::size_t active_prefix(std::uint64_t tick) const {
    const std::size_t n = start_.size();
    std::size_t active = 0;
    while (active < n && start_[active] + length_[active] == tick) ++active;
    const std::size_t strays = par::sum<std::size_t>(n - active, [&](std::size_t k) {
      return std::size_t{start_[active + k] + length_[active + k] == tick};
    });
    if (strays > 0) throw std::logic_error("block timesteps: the active particles are not a prefix");
    return active;
  }

  // Stable counting sort of the first `count` particles (and this integrator's per-particle state)
  // by step length, shortest first; nothing is moved when they are in order already. At the start
  // of a cycle (just after the particles were put in cell order), so that each bin keeps that order.
  void sort_by_length(Particles<D>& p, std::size_t count) {
    if (std::is_sorted(length_.begin(), length_.begin() + static_cast<std::ptrdiff_t>(count))) return;
    const std::array<std::size_t, kMaxBins + 2> first = bin_starts(count);
    std::array<std::size_t, kMaxBins + 2> next = first;
    order_.resize(count);
    for (std::size_t i = 0; i < count; ++i) order_[next[bin(i)]++] = static_cast<std::uint32_t>(i);
    for_each_array(p, [this](auto& v) { par::permute_prefix(v, order_, "integration"); });
  }

  // The same grouping inside a cycle, moving only the particles outside their bin's range: the k-th
  // of those that belong to bin b (in memory order) takes the k-th place in b's range held by a
  // particle of another bin. A stable sort moved 97% of the prefix (a particle that changes bin
  // shifts every one between its old and new place: 100k ring, 20 block cycles, 7.4M moves of
  // 7.6M sorted) where 16% lay outside their bin's range. Memory order changes no particle's
  // values (the pair sums follow cell order), only the round-off of sums over all particles such
  // as the diagnostics' energy, and it is the same for any thread count.
  void group_by_length(Particles<D>& p, std::size_t count) {
    if (std::is_sorted(length_.begin(), length_.begin() + static_cast<std::ptrdiff_t>(count))) return;
    const std::array<std::size_t, kMaxBins + 2> first = bin_starts(count);
    // Out-of-range particles (sources) and the places they leave (holes), each counted by bin.
    std::array<std::size_t, kMaxBins + 2> source_at{}, hole_at{};
    std::size_t region = 0, misplaced = 0;
    for (std::size_t k = 0; k < count; ++k) {
      while (k >= first[region + 1]) ++region;
      const std::size_t b = bin(k);
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
      const std::size_t b = bin(k);
      if (b == region) continue;
      order_[source_at[b]++] = static_cast<std::uint32_t>(k);
      holes_[hole_at[region]++] = static_cast<std::uint32_t>(k);
    }
    for_each_array(p, [this](auto& v) { par::move_values(v, order_, holes_, "integration"); });
  }

  // f(v) for every per-particle array that moves with the particles: the fields and this
  // integrator's own, each in turn, in parallel inside f (a serial Particles::gather was most of
  // this integrator's own time).
  template <class F>
  void for_each_array(Particles<D>& p, F&& f) {
    p.for_each_field([&f](const FieldInfo&, auto& v) { f(v); });
    f(start_);
    f(length_);
    f(v_kick_);
    if (!u_half_.empty()) f(u_half_);
  }

  std::size_t bin(std::size_t i) const { return static_cast<std::size_t>(std::countr_zero(length_[i])); }

  // first[k]: where the particles of 2^k ticks start among the first `count` once grouped by length.
  std::array<std::size_t, kMaxBins + 2> bin_starts(std::size_t count) const {
    std::array<std::size_t, kMaxBins + 2> first{};
    for (std::size_t i = 0; i < count; ++i) ++first[bin(i) + 1];
    for (std::size_t k = 1; k < first.size(); ++k) first[k] += first[k - 1];
    return first;
  }

  IntegratorParams params_;
  RateEvaluator<D>& rates_;
  std::vector<Ticks> start_, length_;
  std::vector<Vec<D>> v_kick_;  // velocity after the opening kick, moved in the point-mass field since
  std::vector<double> u_half_;
  std::vector<std::uint32_t> order_, holes_;
};

template <int D>
std::unique_ptr<Integrator<D>> make_block_leapfrog(const IntegratorParams& params, RateEvaluator<D>& rates) {
  return std::make_unique<BlockLeapfrog<D>>(params, rates);
}

template std::unique_ptr<Integrator<2>> make_block_leapfrog(const IntegratorParams&, RateEvaluator<2>&);
template std::unique_ptr<Integrator<3>> make_block_leapfrog(const IntegratorParams&, RateEvaluator<3>&);

}  // namespace sphdisk
