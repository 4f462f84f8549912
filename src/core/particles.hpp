#pragma once
// Particle storage as a structure of arrays, generated from ONE field table. The same table drives
// reordering, snapshot output, checkpoints and (later) MPI packing, so no list of fields is ever
// kept in step with the storage by hand.
#include <cstdint>
#include <string_view>
#include <type_traits>
#include <vector>

#include "core/snug_resize.hpp"
#include "core/vec.hpp"

namespace sphdisk {

enum FieldFlag : unsigned {
  kSnapshot = 1u << 0,    // written to every snapshot (GADGET/SWIFT dataset name given in the table)
  kCheckpoint = 1u << 1,  // needed to restart bit-for-bit
  kEnergyOnly = 1u << 2,  // only meaningful when internal energy is evolved
  kReduced = 1u << 3,     // recomputed from the others at every evaluation and read only by the pair
                          // loops: stored in single precision in a build with
                          // SPHDISK_SINGLE_PRECISION_FIELDS (arithmetic and sums stay double). Not
                          // the volume m/rho: the force loop's m_j / rho_j must equal it to double
                          // rounding, or kinetic + internal energy would not balance exactly.
  kRateState = 1u << 4,   // read from the particles an evaluation does not update: with block
                          // timesteps a cycle's first partial evaluation reads those of the last
                          // full one, so their checkpoints hold these too (io/checkpoint.hpp)
  kStepState = 1u << 5,   // a particle's state inside an integrator's step (block timesteps: its
                          // step's start and length, the velocity and energy after its opening
                          // kick); held by checkpoints written inside a step (io/checkpoint.hpp)
  kEnergyStepState = 1u << 6,  // such state that only an energy equation needs (absent without one;
                               // since kEnergyOnly fields are absent then too, kept for the
                               // checkpoints of format 5, whose AbsentFields name it)
  kForceCorrectionOnly = 1u << 7,  // read and written only where a force reads the moment correction
                                   // (sph.force_correction, or the consistent viscous force)
  kMixedCorrectionOnly = 1u << 8,  // read and written only where the consistent viscous force uses the
                                   // mixed correction (PhysicsParams::keeps_correction_shift)
  // Which of a rate evaluation's ghost refreshes (domain/particle_domain.hpp, GhostStage) carries the
  // field from its owner to the ranks that hold it as a ghost: after the smoothing-length solve,
  // after the density pass, after the stress pass.
  kHaloSmoothingLength = 1u << 9,
  kHaloDensity = 1u << 10,
  kHaloStress = 1u << 11,
  kArtificialViscosityOnly = 1u << 12,  // read and written only with the artificial viscosity
                                        // (PhysicsParams::av_alpha > 0)
  kScatterDensityOnly = 1u << 13,  // read and written only where the consistent viscous force compares
                                   // scatter densities (PhysicsParams::keeps_scatter_density)
  kOwnerOnly = 1u << 14,  // read only for the particle itself (its integration, its next h, its
                          // step), never as another's neighbour: ghosts come without it
};

// Whether the kReduced fields are stored as float (CMake option SPHDISK_SINGLE_PRECISION_FIELDS).
#ifdef SPHDISK_SINGLE_PRECISION_FIELDS
inline constexpr bool kSinglePrecisionFields = true;
#else
inline constexpr bool kSinglePrecisionFields = false;
#endif
using ReducedReal = std::conditional_t<kSinglePrecisionFields, float, double>;

enum class FieldKind { Id, Ticks, Scalar, Vector, Tensor };

// name, kind, snapshot dataset name, flags, unit dimension (length, mass, time exponents) for output.
// clang-format off
#define SPHDISK_PARTICLE_FIELDS(X)                                                              \
  X(id,    Id,     "ParticleIDs",        kSnapshot | kCheckpoint,               0,  0,  0)     \
  X(mass,  Scalar, "Masses",             kSnapshot | kCheckpoint,               0,  1,  0)     \
  X(pos,   Vector, "Coordinates",        kSnapshot | kCheckpoint,               1,  0,  0)     \
  X(vel,   Vector, "Velocities",         kSnapshot | kCheckpoint,               1,  0, -1)     \
  X(u,     Scalar, "InternalEnergy",     kSnapshot | kCheckpoint | kEnergyOnly, 2,  0, -2)     \
  X(h,     Scalar, "SmoothingLength",    kSnapshot | kCheckpoint | kHaloSmoothingLength, 1, 0, 0) \
  X(rho,   Scalar, "Density",            kSnapshot | kReduced | kRateState | kHaloDensity, -2, 1, 0) \
  X(volume, Scalar, "Volume",            kRateState | kHaloDensity,             2,  0,  0)     \
  X(stress, Tensor, "KinematicStress",   kReduced | kRateState | kHaloStress,   2,  0, -1)     \
  X(correction, Tensor, "MomentCorrection", kReduced | kRateState | kForceCorrectionOnly | kHaloStress, 0, 0, 0) \
  X(correction_shift, Vector, "MomentCorrectionShift", kRateState | kMixedCorrectionOnly | kHaloStress, -1, 0, 0) \
  X(av_limiter, Scalar, "ViscosityLimiter", kRateState | kArtificialViscosityOnly | kHaloStress, 0, 0, 0)     \
  X(signal_speed, Scalar, "SignalSpeed", kRateState | kArtificialViscosityOnly | kOwnerOnly, 1, 0, -1) \
  X(acc,   Vector, "Acceleration",       kSnapshot | kCheckpoint | kOwnerOnly,  1,  0, -2)     \
  X(du_dt, Scalar, "InternalEnergyRate", kCheckpoint | kEnergyOnly | kOwnerOnly, 2, 0, -3)     \
  X(h_prev, Scalar, "PreviousSmoothingLength", kCheckpoint | kOwnerOnly,        1,  0,  0)     \
  X(h_prev2, Scalar, "EarlierSmoothingLength", kCheckpoint | kOwnerOnly,        1,  0,  0)     \
  X(step_ticks, Ticks, "StepTicks",      kStepState | kOwnerOnly,               0,  0,  0)     \
  X(v_kick, Vector, "KickedVelocity",    kStepState | kOwnerOnly,               1,  0, -1)     \
  X(u_kick, Scalar, "KickedInternalEnergy", kStepState | kEnergyOnly | kEnergyStepState | kOwnerOnly, 2, 0, -2) \
  X(av_alpha, Scalar, "ViscosityAlpha",  kSnapshot | kCheckpoint | kArtificialViscosityOnly | kHaloStress, 0, 0, 0) \
  X(compression, Scalar, "Compression",  kArtificialViscosityOnly | kOwnerOnly,  0,  0, -1)     \
  X(scatter_density, Scalar, "ScatterDensity", kRateState | kScatterDensityOnly | kHaloStress, -2, 1, 0)
// clang-format on
// av_alpha, compression: the artificial viscosity's alpha of each particle, and the rate max(-div v, 0)
// of the last evaluation that drives its time-dependent switch (physics/viscosity_switch.hpp); last,
// so that the checkpoints' checksums of the fields before them keep their field indices.
// scatter_density: sum_j m_j W(r_ij, h_j), self term included (physics/scatter_density.hpp), summed
// with the velocity gradient and sent to the ghosts with the stress; after compression for the
// same reason.
// h_prev, h_prev2: the particle's two smoothing-length solutions before h, from which the next
// solve starts (physics/smoothing_length.hpp, predicted_smoothing_length); checkpointed so that a
// resumed run starts its solves where the uninterrupted one would.
// step_ticks, v_kick, u_kick: block timesteps' per-particle state (integrate/block_leapfrog.cpp):
// the start of the particle's current step on the cycle's integer time line (high 32 bits) and its
// length in ticks (low 32 bits), and its velocity and internal energy after the step's opening half
// kick. Fields rather than the integrator's own arrays so that they move with the particles (sorts,
// ranks) and a checkpoint written inside a block cycle can hold them.
// Density is the surface density in 2D (mass / length^2); in 3D its length exponent is -3 (see
// field_length_exponent below).

// The fields a run does not use, to be made absent (Particles::set_absent_fields): the block
// integrator's state inside a step without block timesteps, the energy equation's fields without
// one, the moment correction where no force reads it (PhysicsParams::keeps_correction), its shift
// where no force reads that (keeps_correction_shift), the artificial viscosity's limiter and signal
// speeds without it, the scatter density where no force reads it.
constexpr unsigned unused_fields(bool step_state, bool energy, bool moment_correction, bool correction_shift,
                                 bool artificial_viscosity, bool scatter_density) {
  return (step_state ? 0u : unsigned{kStepState}) | (energy ? 0u : unsigned{kEnergyOnly | kEnergyStepState}) |
         (moment_correction ? 0u : unsigned{kForceCorrectionOnly}) | (correction_shift ? 0u : unsigned{kMixedCorrectionOnly}) |
         (artificial_viscosity ? 0u : unsigned{kArtificialViscosityOnly}) |
         (scatter_density ? 0u : unsigned{kScatterDensityOnly});
}

template <int D>
struct FieldTypes {
  using Id = std::uint64_t;
  using Ticks = std::uint64_t;
  using Scalar = double;
  using Vector = Vec<D>;
  using Tensor = Mat<D>;
};
template <int D>
struct ReducedFieldTypes {  // kReduced fields (scalars and tensors only)
  using Scalar = ReducedReal;
  using Tensor = Mat<D, ReducedReal>;
};
template <int D, unsigned Flags>
using FieldTypesFor = std::conditional_t<(Flags & kReduced) != 0, ReducedFieldTypes<D>, FieldTypes<D>>;

struct FieldInfo {
  std::string_view name;
  FieldKind kind;
  std::string_view dataset;
  unsigned flags;
  int length_exp, mass_exp, time_exp;
};

template <int D>
struct Particles {
#define SPHDISK_DECLARE_FIELD(name, kind, ds, flags, l, m, t) \
  std::vector<typename FieldTypesFor<D, (flags)>::kind> name;
  SPHDISK_PARTICLE_FIELDS(SPHDISK_DECLARE_FIELD)
#undef SPHDISK_DECLARE_FIELD

  std::size_t size() const { return id.size(); }
  std::size_t bytes() const {  // memory held by all fields (capacities)
    std::size_t b = 0;
    for_each_field([&b](const FieldInfo&, const auto& v) { b += v.capacity() * sizeof(v[0]); });
    return b;
  }

  // Calls f(info, field_vector) for every present field (all but the absent ones, below) in table
  // order.
  template <class F>
  void for_each_field(F&& f) {
#define SPHDISK_VISIT_FIELD(name_, kind_, ds_, flags_, l_, m_, t_)                                              \
  if (!((flags_) & absent_))                                                                                 \
    f(FieldInfo{#name_, FieldKind::kind_, ds_, flags_, field_length_exp(l_, FieldKind::kind_, ds_), m_, t_}, name_);
    SPHDISK_PARTICLE_FIELDS(SPHDISK_VISIT_FIELD)
  }
  template <class F>
  void for_each_field(F&& f) const {
    SPHDISK_PARTICLE_FIELDS(SPHDISK_VISIT_FIELD)
#undef SPHDISK_VISIT_FIELD
  }

  // Calls f(info, field, other's same field) for every field present in both, in table order
  // (copies between two sets of particles, e.g. a partial evaluation's involved particles,
  // evaluate/rate_evaluator.cpp).
  template <class F>
  void for_each_field_with(const Particles& other, F&& f) {
#define SPHDISK_VISIT_FIELD_WITH(name_, kind_, ds_, flags_, l_, m_, t_)                                             \
  if (!((flags_) & (absent_ | other.absent_)))                                                                  \
    f(FieldInfo{#name_, FieldKind::kind_, ds_, flags_, field_length_exp(l_, FieldKind::kind_, ds_), m_, t_}, name_, \
      other.name_);
    SPHDISK_PARTICLE_FIELDS(SPHDISK_VISIT_FIELD_WITH)
#undef SPHDISK_VISIT_FIELD_WITH
  }

  // Absent fields: those flagged with any of absent_fields(), left empty and skipped by every
  // for_each_field, so state that only some runs use costs the others nothing (kStepState: block
  // timesteps only, 32 bytes per particle; kEnergyOnly: u, du_dt and u_kick, 16-24 bytes, with an
  // energy equation only; kForceCorrectionOnly: the moment correction, 32 bytes, with the force
  // correction only; a run's choice: unused_fields above). Physics that may write an absent field
  // tests for it (the viscous heating and pressure work: du_dt). set_absent_fields(flags) empties
  // the fields flagged with any of `flags` and makes the others present (sized to the particles;
  // zero where they were absent). Copies of particles made field by field (a rank's share of a
  // file) take the source's.
  unsigned absent_fields() const { return absent_; }
  void set_absent_fields(unsigned flags) {
    const std::size_t n = size();
    absent_ = 0;
    for_each_field([n, flags](const FieldInfo& info, auto& v) {
      if (info.flags & flags) std::remove_reference_t<decltype(v)>().swap(v);
      else if (v.size() != n) v.assign(n, {});
    });
    absent_ = flags;
  }

  // Exact when the fields are first made (initial conditions, a checkpoint read); later growth
  // (ghosts appended) keeps a margin.
  void resize(std::size_t n) {
    for_each_field([n](const FieldInfo&, auto& v) {
      if (v.capacity() == 0) v.reserve(n);
      resize_snug(v, n);
    });
  }

  // new[i] = old[order[i]] for every field (order is a permutation or a selection of indices),
  // each field replaced by an exact-size copy. Serial: it also runs in the child process that reads
  // a checkpoint (io/hdf5_util.hpp forks to isolate library crashes), where an OpenMP loop would
  // wait for threads that do not exist there. The run's reorder rearranges each field in place
  // with par::permute_prefix (app/runner.cpp), as the block integrator's moves of a prefix do.
  void gather(const std::vector<std::uint32_t>& order) {
    for_each_field([&order](const FieldInfo&, auto& v) {
      std::remove_reference_t<decltype(v)> out(order.size());
      for (std::size_t i = 0; i < order.size(); ++i) out[i] = v[order[i]];
      v.swap(out);
    });
  }

 private:
  unsigned absent_ = 0;

  // Density is per area in 2D, per volume in 3D.
  static constexpr int field_length_exp(int l, FieldKind, std::string_view ds) {
    return ds == std::string_view("Density") || ds == std::string_view("ScatterDensity") ? -D : l;
  }
};

}  // namespace sphdisk
