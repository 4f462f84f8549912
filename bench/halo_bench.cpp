// The time of one halo build (Halo::build: choosing and sending the ghosts) on the ranks it is
// started on: N particles per rank, uniform in 3D, rank r in the slab r/P <= x < (r+1)/P of the
// unit cube, ~58 neighbours, the top grid the code makes (256 per rank or N/8 cells). Particles in
// the order of a grid of kernel-size cells (as the code's reordering leaves them), or random.
//   cmake --build --preset release --target halo_bench
//   mpirun -np 2 -x OMP_NUM_THREADS=1 build/release/bench/halo_bench 200000 [random]
// Prints per rank: ghosts and the fastest of 5 builds.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <string>

#include "domain/decomposition.hpp"
#include "domain/distributed_domain.hpp"

int main(int argc, char** argv) {
  using namespace sphdisk;
  MpiSession session(argc, argv);
  const Communicator comm = Communicator::world();
  const std::size_t n = argc > 1 ? std::stoul(argv[1]) : 200000;
  const bool random_order = argc > 2 && std::string(argv[2]) == "random";
  const int ranks = comm.size(), r = comm.rank();
  std::mt19937_64 rng(1234 + static_cast<unsigned>(r));
  std::uniform_real_distribution<double> u(0, 1);
  Particles<3> p;
  p.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    p.pos[i] = Vec<3>{(r + u(rng)) / ranks, u(rng), u(rng)};
    p.id[i] = static_cast<std::uint64_t>(r) * n + i;
  }
  const double total = static_cast<double>(n) * ranks;
  const double support = std::cbrt(58 * 3 / (4 * M_PI * total));  // 2h of ~58 neighbours
  if (!random_order) {
    auto key = [&](std::uint32_t i) {
      const Vec<3>& x = p.pos[i];
      return std::array<int, 3>{int(x[2] / support), int(x[1] / support), int(x[0] / support)};
    };
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
    p.gather(order);
  }
  const Lattice<3> lattice = make_lattice<3>(Vec<3>{0, 0, 0}, Vec<3>{1, 1, 1}, static_cast<std::size_t>(total), 0.5 * support);
  const Decomposition<3> grid =
      make_top_grid(lattice, std::max<std::size_t>(256 * static_cast<std::size_t>(ranks), static_cast<std::size_t>(total) / 8));
  const double reach = 1.25 * support, need = 1.05 * reach;  // the halo's margin over the support
  Halo<3> halo;
  double best = 1e30;
  for (int k = 0; k < 5; ++k) {
    comm.barrier();
    const auto t0 = std::chrono::steady_clock::now();
    halo.build(comm, grid, p, [&](std::size_t) { return need; }, [&](std::size_t) { return reach; });
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    halo.drop(p);
  }
  std::printf("rank %d: %zu particles, %s order, %zu top cells, %zu ghosts, fastest build %.4f s\n", r, n,
              random_order ? "random" : "grid", grid.top_cells(), halo.ghosts(), best);
}
