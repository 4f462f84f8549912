#include "app/diagnostics.hpp"

#include "parallel/loops.hpp"

namespace sphdisk {

template <int D>
GlobalSums global_sums(const Particles<D>& p, bool energy) {
  return par::sum<GlobalSums>(p.size(), [&](std::size_t i) {
    const double m = p.mass[i];
    return GlobalSums{m, 0.5 * m * norm2(p.vel[i]), energy ? m * p.u[i] : 0.0,
                      m * angular_momentum_z(p.pos[i], p.vel[i])};
  });
}

template GlobalSums global_sums(const Particles<2>&, bool);
template GlobalSums global_sums(const Particles<3>&, bool);

}  // namespace sphdisk
