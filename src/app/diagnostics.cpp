#include "app/diagnostics.hpp"

#include "parallel/order_free_sum.hpp"

namespace sphdisk {

template <int D>
GlobalSums global_sums(const Communicator& comm, const Particles<D>& p, bool energy) {
  const auto s = order_free_sums<4>(comm, p.size(), [&](std::size_t i) {
    const double m = p.mass[i];
    return std::array<double, 4>{m, 0.5 * m * norm2(p.vel[i]), energy ? m * p.u[i] : 0.0,
                                 m * angular_momentum_z(p.pos[i], p.vel[i])};
  });
  return GlobalSums{s[0], s[1], s[2], s[3]};
}

template GlobalSums global_sums(const Communicator&, const Particles<2>&, bool);
template GlobalSums global_sums(const Communicator&, const Particles<3>&, bool);

}  // namespace sphdisk
