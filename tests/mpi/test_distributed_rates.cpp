// Distributed-memory rate evaluation (run under mpirun with 2, 3, ... ranks): the particles are
// spread over the ranks, decomposed, migrated and given ghosts; every owned particle's density,
// stress and acceleration must equal, bit for bit, those of one process holding all particles.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

#include "evaluate/rate_evaluator.hpp"
#include "parallel/timers.hpp"
#include "domain/distributed_domain.hpp"
#include "parallel/communicator.hpp"
#include "problems/ring_setup.hpp"

using namespace sphdisk;

namespace {

RingSetup ring(std::size_t n) {
  RingSetup s;
  s.solution = RingSolution{1e-10, 1.0, 4.778e-5};
  s.placement.particles = n;
  return s;
}

template <class T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// Rotates every particle by `angle` about the centre (a large drift: ownership becomes stale).
void rotate(Particles<2>& p, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  for (auto& x : p.pos) x = Vec<2>{{c * x[0] - s * x[1], s * x[0] + c * x[1]}};
}

// Runs the evaluation on the ranks and checks every owned particle against one process holding
// all particles (by ID). With `drift`, the particles move after the decomposition (as during a
// step), so many of them lie in other ranks' top cells when the ghosts are chosen.
// Adaptive smoothing starts from h_start_factor x the ring's typical h: far from the solution, so
// the halo chosen from the start values is too small and must be widened.
// With clump_mass != 1, the particles within 0.15 r0 of (0, r0) have that times their mass.
void expect_distributed_equals_serial(const PhysicsParams& phys, std::size_t n, std::size_t top_cells_per_rank,
                                      double drift = 0.0, Smoothing smoothing = Smoothing::Constant,
                                      double h_start_factor = 1.0, double clump_mass = 1.0) {
  const Communicator comm = Communicator::world();
  const RingSetup s = ring(n);
  const double h = ring_smoothing_length(s, 60);
  const auto weigh = [clump_mass](Particles<2>& q) {
    for (std::size_t i = 0; i < q.size(); ++i)
      if (std::hypot(q.pos[i][0], q.pos[i][1] - 1.0) < 0.15) q.mass[i] *= clump_mass;
  };

  Particles<2> all = make_ring(s);
  weigh(all);
  rotate(all, drift);
  for (auto& hi : all.h) hi = h * h_start_factor;
  PhaseTimers timers;
  RateEvaluator<2> serial(KernelType::Cubic, h, phys, timers, smoothing, 60);
  serial.evaluate(all);
  std::map<std::uint64_t, std::size_t> index_of;
  for (std::size_t i = 0; i < all.size(); ++i) index_of[all.id[i]] = i;

  // Each rank starts from a scattered share (as after reading a file), not from its domain.
  Particles<2> p = make_ring(s);
  weigh(p);
  for (auto& hi : p.h) hi = h * h_start_factor;
  std::vector<std::uint32_t> mine;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (static_cast<int>(i % static_cast<std::size_t>(comm.size())) == comm.rank()) mine.push_back(static_cast<std::uint32_t>(i));
  p.gather(mine);

  DistributedDomain<2> domain(comm, 1.05, top_cells_per_rank);
  domain.rebalance(p, h);
  const Decomposition<2> d = decompose(comm, p, h, top_cells_per_rank);
  for (std::size_t i = 0; i < p.size(); ++i) ASSERT_EQ(d.owner_of(p.pos[i]), comm.rank());
  rotate(p, drift);
  RateEvaluator<2> rates(KernelType::Cubic, h, phys, timers, smoothing, 60);
  rates.set_domain(&domain);
  rates.evaluate(p);
  // The start values far below the solution must have made the halo too small at first.
  if (comm.size() > 1 && smoothing == Smoothing::Adaptive && h_start_factor < 0.5) EXPECT_GT(rates.halo_widenings(), 0u);

  // Every particle is owned by exactly one rank, and no rank holds them all (beyond 1 rank).
  EXPECT_EQ(comm.sum(p.size()), n);
  if (comm.size() > 1) {
    EXPECT_GT(domain.halo().ghosts(), 0u);
    // With one h for all the halo is a thin layer. (Adaptive h: a few thousand particles have
    // supports as wide as a rank's share of the ring, so no bound is asserted at this size.)
    if (smoothing == Smoothing::Constant) EXPECT_LT(p.size() + domain.halo().ghosts(), n);
  }
  std::size_t mismatches = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::size_t r = index_of.at(p.id[i]);
    const bool same = same_bits(p.h[i], all.h[r]) && same_bits(p.rho[i], all.rho[r]) && same_bits(p.stress[i], all.stress[r]) &&
                      same_bits(p.acc[i], all.acc[r]) && same_bits(p.du_dt[i], all.du_dt[r]);
    if (!same && ++mismatches <= 3)
      ADD_FAILURE() << "rank " << comm.rank() << " particle ID " << p.id[i] << ": acc " << p.acc[i][0] << " vs "
                    << all.acc[r][0] << ", rho " << p.rho[i] << " vs " << all.rho[r];
  }
  EXPECT_EQ(mismatches, 0u) << "rank " << comm.rank() << " of " << comm.size();
}

}  // namespace

TEST(DistributedRates, SameBitsAsOneProcess) {
  PhysicsParams phys;
  phys.nu = 4.778e-5;
  phys.evolve_energy = true;
  expect_distributed_equals_serial(phys, 6000, 256);
}

TEST(DistributedRates, SameBitsWithPressureAndForceCorrection) {
  PhysicsParams phys;
  phys.nu = 4.778e-5;
  phys.nu_bulk = 1e-5;
  phys.eos = EquationOfState::Isothermal;
  phys.sound_speed = 0.05;
  phys.evolve_energy = true;
  phys.force_correction = true;
  expect_distributed_equals_serial(phys, 5000, 256);
}

// The mixed gradient correction: its shift C~ e is a ghost field read by the consistent force.
TEST(DistributedRates, MixedCorrectionSameBitsAsOneProcess) {
  PhysicsParams phys;
  phys.nu = 4.778e-5;
  phys.gradient_correction = GradientCorrection::Mixed;
  expect_distributed_equals_serial(phys, 6000, 256, 0.2, Smoothing::Adaptive, 1.0);
}

TEST(DistributedRates, SameBitsAfterParticlesLeftTheirRanksCells) {
  PhysicsParams phys;
  phys.nu = 4.778e-5;
  expect_distributed_equals_serial(phys, 5000, 256, 0.4);
}

TEST(DistributedRates, AdaptiveSmoothingSameBitsAsOneProcess) {
  PhysicsParams phys;
  phys.nu = 4.778e-5;
  phys.evolve_energy = true;
  expect_distributed_equals_serial(phys, 6000, 256, 0.0, Smoothing::Adaptive, 1.0);
}

// Masses that differ in one place only: every rank must take the summed density's form for
// unequal masses (smoothing_length.hpp), also a rank whose own and ghost particles are all alike.
TEST(DistributedRates, AdaptiveSmoothingWithUnequalMassesSameBitsAsOneProcess) {
  PhysicsParams phys;
  phys.nu = 4.778e-5;
  expect_distributed_equals_serial(phys, 6000, 256, 0.0, Smoothing::Adaptive, 1.0, 1.5);
}

TEST(DistributedRates, AdaptiveSmoothingWidensTheHaloWhenHGrows) {
  PhysicsParams phys;
  phys.nu = 4.778e-5;
  phys.force_correction = true;
  expect_distributed_equals_serial(phys, 6000, 256, 0.3, Smoothing::Adaptive, 0.3);  // h grows ~3x
}

TEST(DistributedRates, AdaptiveSmoothingWhenHShrinks) {
  PhysicsParams phys;
  phys.nu = 4.778e-5;
  expect_distributed_equals_serial(phys, 5000, 64, 0.0, Smoothing::Adaptive, 3.0);
}

TEST(DistributedRates, SameBitsWithCoarseTopCells) {
  PhysicsParams phys;
  phys.nu = 4.778e-5;
  expect_distributed_equals_serial(phys, 4000, 4);  // few, large top cells: uneven shares
}

// The owners are kept while the particle counts they give stay within the threshold, and cut anew
// past it; every particle ends on the owner of its top cell either way.
TEST(DistributedDomain, RebalancesOnlyPastTheThreshold) {
  const Communicator comm = Communicator::world();
  if (comm.size() == 1) GTEST_SKIP() << "one rank has nothing to balance";
  const RingSetup s = ring(6000);
  const double h = ring_smoothing_length(s, 60);
  Particles<2> p = make_ring(s, static_cast<std::size_t>(comm.rank()), static_cast<std::size_t>(comm.size()));
  DistributedDomain<2> domain(comm, 1.05);
  domain.rebalance(p, h);
  EXPECT_EQ(domain.recuts(), 1u);
  EXPECT_LE(domain.imbalance(), 1.05);
  const Decomposition<2> first = decompose(comm, p, h, 256);
  rotate(p, 1e-4);  // a small drift: the counts hardly change
  domain.rebalance(p, h);
  EXPECT_EQ(domain.recuts(), 1u);
  for (const auto& x : p.pos) ASSERT_EQ(first.owner_of(x), comm.rank());
  for (auto& x : p.pos) x = Vec<2>{{0.3 * x[0] * x[0], 0.3 * x[1]}};  // squeezed to one side: unbalanced
  domain.rebalance(p, h);
  EXPECT_EQ(domain.recuts(), 2u);
  const double largest = comm.max(static_cast<double>(p.size()));
  EXPECT_LE(largest * comm.size() / static_cast<double>(comm.sum(p.size())), 1.05);
  const Decomposition<2> now = decompose(comm, p, h, 256);
  for (const auto& x : p.pos) ASSERT_EQ(now.owner_of(x), comm.rank());
}

// Only particles that read ghosts (need >= 0: the active ones of a block step) draw them: with
// none reading, no rank gets a ghost; with a few reading, every other rank's particle within the
// radius of one of them arrives (checked against all particles), and fewer than when all read.
TEST(DistributedDomain, OnlyParticlesThatReadGhostsDrawThem) {
  const Communicator comm = Communicator::world();
  if (comm.size() == 1) GTEST_SKIP() << "one rank has no ghosts";
  const RingSetup s = ring(6000);
  const double h = ring_smoothing_length(s, 60), radius = 2.2 * h;
  Particles<2> p = make_ring(s, static_cast<std::size_t>(comm.rank()), static_cast<std::size_t>(comm.size()));
  DistributedDomain<2> domain(comm);
  domain.rebalance(p, h);
  const std::size_t owned = p.size();
  // "Active": the particles within 0.3 r0 of the point (r0, 0), wherever they are owned.
  const auto active = [](const Vec<2>& x) { return std::hypot(x[0] - 1.0, x[1]) < 0.3; };
  const auto ghosts_with = [&](auto need) {
    domain.add_ghosts(p, h, need, [&](std::size_t) { return radius; });
    const std::vector<std::uint64_t> ids(p.id.begin() + static_cast<std::ptrdiff_t>(owned), p.id.end());
    domain.remove_ghosts(p);
    return ids;
  };
  EXPECT_EQ(comm.sum(ghosts_with([](std::size_t) { return -1.0; }).size()), 0u);
  const std::size_t all_read = comm.sum(ghosts_with([&](std::size_t) { return radius; }).size());
  const std::vector<std::uint64_t> got = ghosts_with([&](std::size_t i) { return active(p.pos[i]) ? radius : -1.0; });
  EXPECT_LT(comm.sum(got.size()), all_read);
  const Particles<2> all = make_ring(s);
  std::vector<char> mine(all.size() + 1, 0);
  for (const std::uint64_t id : p.id) mine[id] = 1;
  std::vector<char> arrived(all.size() + 1, 0);
  for (const std::uint64_t id : got) arrived[id] = 1;
  std::size_t missing = 0;
  for (std::size_t i = 0; i < owned; ++i) {
    if (!active(p.pos[i])) continue;
    for (std::size_t j = 0; j < all.size(); ++j)
      if (!mine[all.id[j]] && norm(all.pos[j] - p.pos[i]) < radius && !arrived[all.id[j]]) ++missing;
  }
  EXPECT_EQ(missing, 0u) << "rank " << comm.rank();
}

// Ghosts by each reader's own need, whichever ranks read the same top cell, and by the sender's
// reach even where that is negative. Three ranks, top cells of 1 x 1 on [0, 8] x [0, 2]: rank 0
// (at (2.5, 0.5), reach 0.5, reading nothing), rank 1 and rank 2 reading in cell (0, 0) with needs
// 3 and 0.5. Rank 0's particle, 1.5 from the cell, goes to rank 1 only; ranks 1 and 2 share the
// cell, so each gets the other's. Then rank 0's particle (reach -1) 0.05 from rank 2's cell, rank 1
// far and reading nothing: it goes to rank 2.
TEST(DistributedDomain, EachReaderGetsTheGhostsWithinItsOwnNeed) {
  const Communicator comm = Communicator::world();
  if (comm.size() != 3) GTEST_SKIP() << "a set-up of three ranks";
  Decomposition<2> grid;
  grid.lattice.lo = Vec<2>{0.0, 0.0};
  grid.lattice.cell_size = 1.0;
  grid.lattice.dims = {8, 2};
  grid.top_dims = {8, 2};
  grid.owner.assign(16, 0);
  const auto ghosts_of = [&](const std::array<Vec<2>, 3>& at, std::array<double, 3> need, std::array<double, 3> reach) {
    Particles<2> p;
    p.resize(1);
    const auto r = static_cast<std::size_t>(comm.rank());
    p.pos[0] = at[r];
    p.id[0] = 100 + r;
    Halo<2> halo;
    halo.build(comm, grid, p, [&](std::size_t) { return need[r]; }, [&](std::size_t) { return reach[r]; });
    return std::vector<std::uint64_t>(p.id.begin() + 1, p.id.end());
  };
  using Ids = std::vector<std::uint64_t>;
  const std::array<Ids, 3> shared{Ids{}, Ids{100, 102}, Ids{101}};
  EXPECT_EQ(ghosts_of({Vec<2>{2.5, 0.5}, Vec<2>{0.5, 0.5}, Vec<2>{0.6, 0.5}}, {-1, 3, 0.5}, {0.5, 0.1, 0.1}),
            shared[static_cast<std::size_t>(comm.rank())]);
  const std::array<Ids, 3> negative_reach{Ids{}, Ids{}, Ids{100}};
  EXPECT_EQ(ghosts_of({Vec<2>{1.05, 0.5}, Vec<2>{7.5, 1.5}, Vec<2>{0.6, 0.5}}, {-1, -1, 0.5}, {-1, 0.1, 0.1}),
            negative_reach[static_cast<std::size_t>(comm.rank())]);
}

// Each rank's value for rank r arrives on r, by sender: rank s sends 1000 s + r to rank r.
TEST(Communicator, AllToAllDeliversEachRanksValueBySender) {
  const Communicator comm = Communicator::world();
  const auto ranks = static_cast<std::uint64_t>(comm.size()), me = static_cast<std::uint64_t>(comm.rank());
  std::vector<std::uint64_t> send(ranks);
  for (std::uint64_t r = 0; r < ranks; ++r) send[r] = 1000 * me + r;
  const std::vector<std::uint64_t> got = comm.all_to_all(send);
  ASSERT_EQ(got.size(), ranks);
  for (std::uint64_t s = 0; s < ranks; ++s) EXPECT_EQ(got[s], 1000 * s + me);
}

// Every rank's values arrive on every rank, rank after rank: rank s gives {s, 10 s + 1}.
TEST(Communicator, GatherValuesGivesEveryRanksValuesInRankOrder) {
  const Communicator comm = Communicator::world();
  const double me = comm.rank();
  const std::vector<double> mine{me, 10 * me + 1};
  const std::vector<double> got = comm.gather_values(mine);
  ASSERT_EQ(got.size(), 2 * static_cast<std::size_t>(comm.size()));
  for (std::size_t s = 0; s < got.size() / 2; ++s) {
    EXPECT_EQ(got[2 * s], static_cast<double>(s));
    EXPECT_EQ(got[2 * s + 1], 10.0 * static_cast<double>(s) + 1);
  }
}

// A first distribution that moves more particles than one migration round carries (2^15 per
// destination) arrives whole: every particle once, on its owner, with its fields.
TEST(DistributedDomain, LargeMigrationsArriveWhole) {
  const Communicator comm = Communicator::world();
  const RingSetup s = ring(100000);
  Particles<2> p = make_ring(s, static_cast<std::size_t>(comm.rank()), static_cast<std::size_t>(comm.size()));
  const double h = ring_smoothing_length(s, 60);
  DistributedDomain<2> domain(comm);
  domain.rebalance(p, h);
  const Decomposition<2> d = decompose(comm, p, h, 256);
  const Particles<2> all = make_ring(s);
  std::uint64_t id_sum = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    ASSERT_EQ(d.owner_of(p.pos[i]), comm.rank());
    ASSERT_TRUE(same_bits(p.pos[i], all.pos[p.id[i] - 1]) && same_bits(p.vel[i], all.vel[p.id[i] - 1]));
    id_sum += p.id[i];
  }
  EXPECT_EQ(comm.sum(p.size()), all.size());
  EXPECT_EQ(comm.sum(id_sum), all.size() * (all.size() + 1) / 2);  // IDs 1..N
  EXPECT_TRUE(ids_unique(comm, p.id));
}

int main(int argc, char** argv) {
  MpiSession mpi(argc, argv);
  ::testing::InitGoogleTest(&argc, argv);
  // Only rank 0 prints the gtest report; failures on any rank still fail that rank's exit code.
  if (Communicator::world().rank() != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  return RUN_ALL_TESTS();
}
