#include "problems/sedov_blast.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/error.hpp"

namespace sphdisk {

template <int D>
std::size_t sedov_lattice_side(const SedovBlast& s) {
  const auto n = static_cast<std::size_t>(std::llround(std::pow(static_cast<double>(s.particles), 1.0 / D)));
  if (n < 8) throw UserError("problem.particles = " + std::to_string(s.particles) + ": a blast wave needs at least 8 particles per side (" + std::to_string(D == 3 ? 512 : 64) + " in all)");
  return n;
}

template <int D>
double sedov_blast_radius(const SedovBlast& s) {
  const double dx = 1.0 / static_cast<double>(sedov_lattice_side<D>(s));
  const double unit_ball = D == 3 ? 4.0 * std::numbers::pi / 3.0 : std::numbers::pi;
  return dx * std::pow(s.central_particles / unit_ball, 1.0 / D);
}

namespace {

// Lattice point k (0-based, x fastest) of a side of n points with spacing dx, centred on the origin.
template <int D>
Vec<D> lattice_point(std::size_t k, std::size_t n, double dx) {
  Vec<D> x;
  for (int d = 0; d < D; ++d) {
    x[d] = (static_cast<double>(k % n) + 0.5) * dx - 0.5;
    k /= n;
  }
  return x;
}

}  // namespace

template <int D>
Particles<D> make_sedov_blast(const SedovBlast& s, std::size_t share, std::size_t shares) {
  if (shares == 0 || share >= shares) throw std::invalid_argument("make_sedov_blast: share out of range");
  const std::size_t n = sedov_lattice_side<D>(s);
  std::size_t total = 1;
  for (int d = 0; d < D; ++d) total *= n;
  const double dx = 1.0 / static_cast<double>(n), m = 1.0 / static_cast<double>(total);
  const double r_blast = sedov_blast_radius<D>(s);
  // How many lattice points lie within the blast radius (all shares count all of them).
  std::size_t inside = 0;
  for (std::size_t k = 0; k < total; ++k) inside += norm(lattice_point<D>(k, n, dx)) < r_blast;
  // Ambient: P = (gamma - 1) rho u with rho = 1.
  const double u_ambient = SedovBlast::kAmbientPressure * s.energy / (s.gamma - 1.0);
  const double u_blast = s.energy / (static_cast<double>(inside) * m);
  Particles<D> p;
  p.resize(total > share ? (total - share + shares - 1) / shares : 0);
  for (std::size_t k = share, i = 0; k < total; k += shares, ++i) {
    p.id[i] = k + 1;
    p.mass[i] = m;
    p.pos[i] = lattice_point<D>(k, n, dx);
    p.vel[i] = Vec<D>{};
    p.u[i] = u_ambient + (norm(p.pos[i]) < r_blast ? u_blast : 0.0);
  }
  return p;
}

template std::size_t sedov_lattice_side<2>(const SedovBlast&);
template std::size_t sedov_lattice_side<3>(const SedovBlast&);
template double sedov_blast_radius<2>(const SedovBlast&);
template double sedov_blast_radius<3>(const SedovBlast&);
template Particles<2> make_sedov_blast<2>(const SedovBlast&, std::size_t, std::size_t);
template Particles<3> make_sedov_blast<3>(const SedovBlast&, std::size_t, std::size_t);

}  // namespace sphdisk
