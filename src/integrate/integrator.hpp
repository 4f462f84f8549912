#pragma once
// Time integrators. Each advances (pos, vel, u) with the rates of a RateSource (acc, du_dt;
// integrate/rate_source.hpp, implemented by evaluate/rate_evaluator.hpp):
//  - KDK leapfrog: second order, symplectic for the gravity part; no secular radial drift
//    of Kepler orbits (docs/physics.md sec. 3, "accuracy trap").
//  - respa: the same leapfrog on the hydrodynamic forces' own step, with the point mass's gravity
//    substepped per particle inside it (leapfrog.cpp).
//  - block (default): respa with individual power-of-two hydrodynamic steps (block_leapfrog.cpp).
//  - embedded explicit Runge-Kutta with error control (the paper's "error tolerance of the time
//    integrator", P98 sec. 5.3): Bogacki-Shampine 3(2) or Dormand-Prince 5(4).
#include <functional>
#include <limits>
#include <memory>
#include <string>

#include "integrate/rate_source.hpp"
#include "core/error.hpp"
#include "integrate/timestep.hpp"

namespace sphdisk {

enum class Scheme { Leapfrog, Respa, Block, RK45 };
Scheme scheme_from_name(const std::string& name);

// How the block scheme advances the hydrodynamic rates over a particle's step: explicit kicks, whose
// steps the viscous limit h^2 / nu bounds, or Runge-Kutta-Legendre super-steps at the end of each
// step (integrate/super_steps.hpp), with as many stages as the step needs.
enum class ViscousUpdate { Explicit, SuperSteps };
ViscousUpdate viscous_update_from_name(const std::string& name);

struct IntegratorParams {
  Scheme scheme = Scheme::Leapfrog;
  double tolerance = 1e-6;  // RK only: relative error per step in positions and velocities
  TimestepFactors factors;
  double dt_max = std::numeric_limits<double>::infinity();
  ViscousUpdate viscous_update = ViscousUpdate::Explicit;  // block only
  int max_stages = 16;  // super-steps: steps up to rkl2_reach(max_stages) explicit viscous limits
};

template <int D>
class Integrator {
 public:
  virtual ~Integrator() = default;
  // Computes the rates of the initial state.
  virtual void start(Particles<D>& p) = 0;
  // Advances by one step of at most dt_cap; returns the step taken (hits dt_cap exactly when it
  // is the binding limit, so outputs fall on their times).
  virtual double step(Particles<D>& p, double dt_cap) = 0;
  virtual std::size_t rejected_steps() const { return 0; }
  // Memory the integrator holds between steps beyond the particles (capacities, bytes; ranks.json).
  virtual std::size_t bytes() const { return 0; }
  // Whether its next step reads rates of the last step from particles it does not update (block
  // timesteps' partial evaluations read the last full one's density and stress): a checkpoint must
  // then hold them (kRateState, io/checkpoint.hpp), as they cannot be recomputed to the same bits.
  virtual bool needs_rate_state() const { return false; }
  // State the integrator carries between steps beyond the particles (checkpointed).
  virtual std::vector<double> state() const { return {}; }
  virtual void set_state(const std::vector<double>& s) { (void)s; }
  // Between steps all per-particle state lives in Particles (acc and du_dt are checkpointed), so
  // particles may be removed or reordered freely between calls.

  // A step with substeps (a block cycle) is inside_step() between them, where the substep hook
  // below is called: the particles then also carry their kStepState fields, and step_state() is
  // the rest of what the step needs to go on. A checkpoint written there holds both, and
  // resume_inside_step(state) makes the next step() continue the interrupted one (after which it
  // is inside_step() until it goes on). Throws UserError for an integrator without such steps.
  virtual bool inside_step() const { return false; }
  // Whether its steps read and write the particles' kStepState fields (otherwise absent).
  virtual bool keeps_step_state() const { return false; }
  virtual std::vector<double> step_state() const { return {}; }
  virtual void resume_inside_step(const std::vector<double>& s) {
    (void)s;
    throw UserError("the checkpoint was written inside a block-timestep cycle: resume it with integrator.scheme = "
                    "\"block\"");
  }

  // Called between the substeps of a step that has them (block timesteps: after each tick of a
  // cycle but the last, on every rank at the same tick) with the time done and the step's length:
  // a cycle of a large run can take hours, and this is where the caller shows progress and hears
  // a request to stop, or writes a checkpoint (see inside_step above). The hook may throw to leave
  // the step; the particles are then between substeps, which only such a checkpoint may record.
  using SubstepHook = std::function<void(double done, double length)>;
  void on_substep(SubstepHook hook) { substep_hook_ = std::move(hook); }

 protected:
  void substep_done(double done, double length) const {
    if (substep_hook_) substep_hook_(done, length);
  }

 private:
  SubstepHook substep_hook_;
};

template <int D>
std::unique_ptr<Integrator<D>> make_integrator(const IntegratorParams& params, RateSource<D>& rates);

}  // namespace sphdisk
