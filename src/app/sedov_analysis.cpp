#include "app/sedov_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/error.hpp"
#include "problems/sedov_blast.hpp"
#include "problems/sedov_solution.hpp"

namespace sphdisk {

namespace {

// A parameter of the run that wrote the snapshot, as a number.
double number_parameter(const SnapshotMeta& meta, const std::string& key) {
  const std::string text = meta.parameter(key);
  if (text.empty()) throw UserError("snapshot has no parameter " + key + " (not written by a sedov run)");
  return std::stod(text);
}

}  // namespace

template <int D>
SedovComparison compare_sedov(const Particles<D>& p, const SnapshotMeta& meta, int nbins) {
  if (p.u.empty()) throw UserError("snapshot has no InternalEnergy: a blast wave's pressure needs it");
  SedovComparison c;
  c.time = meta.time;
  c.dimension = D;
  c.particles = p.size();
  c.gamma = number_parameter(meta, "physics.gamma");
  c.energy = number_parameter(meta, "problem.blast_energy");
  c.rho0 = 1.0;  // the set-up's cube: side 1, mass 1
  const SedovSolution solution(c.gamma, D);
  c.shock_radius = c.time > 0 ? solution.shock_radius(c.energy, c.rho0, c.time) : 0.0;
  c.initial_energy = c.energy * (1.0 + SedovBlast::kAmbientPressure / (c.gamma - 1.0));
  const double r_max = std::min(c.time > 0 ? 1.5 * c.shock_radius : 0.5, 0.5);
  c.bins.resize(static_cast<std::size_t>(nbins));
  const double width = r_max / nbins;
  for (std::size_t b = 0; b < c.bins.size(); ++b) {
    SedovBin& bin = c.bins[b];
    bin.r_lo = static_cast<double>(b) * width;
    bin.r_hi = bin.r_lo + width;
    // The solution's means over the shell's volume (weights r^(D-1), 32 midpoints).
    double weight = 0;
    for (int k = 0; k < 32; ++k) {
      const double r = bin.r_lo + (k + 0.5) / 32.0 * width, w = std::pow(r, D - 1);
      const auto s = c.time > 0 ? solution.at(r, c.energy, c.rho0, c.time) : SedovSolution::State{c.rho0, 0, 0};
      bin.rho_ana += w * s.rho, bin.vr_ana += w * s.v, bin.p_ana += w * s.p, weight += w;
    }
    bin.rho_ana /= weight, bin.vr_ana /= weight, bin.p_ana /= weight;
  }
  // The L1 norms compare each particle with the solution at its own radius (shells finer than the
  // lattice would hold none); the shells' means are the table's.
  double drho = 0, dv = 0, dp = 0, srho = 0, sv = 0, sp = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double r = norm(p.pos[i]);
    c.total_energy += p.mass[i] * (0.5 * norm2(p.vel[i]) + p.u[i]);
    if (r >= r_max) continue;
    const double rho = p.rho[i], vr = r > 0 ? dot(p.vel[i], p.pos[i]) / r : 0.0, P = (c.gamma - 1.0) * rho * p.u[i];
    const auto s = c.time > 0 ? solution.at(r, c.energy, c.rho0, c.time) : SedovSolution::State{c.rho0, 0, 0};
    drho += std::abs(rho - s.rho), srho += s.rho;
    dv += std::abs(vr - s.v), sv += std::abs(s.v);
    dp += std::abs(P - s.p), sp += s.p;
    SedovBin& bin = c.bins[std::min(c.bins.size() - 1, static_cast<std::size_t>(r / width))];
    ++bin.count;
    bin.rho += rho, bin.vr += vr, bin.p += P;
  }
  for (SedovBin& bin : c.bins) {
    if (bin.count == 0) continue;
    const double n = static_cast<double>(bin.count);
    bin.rho /= n, bin.vr /= n, bin.p /= n;
    if (bin.rho > c.peak_density) c.peak_density = bin.rho, c.peak_radius = 0.5 * (bin.r_lo + bin.r_hi);
  }
  c.rho_l1 = drho / srho;
  c.vr_l1 = sv > 0 ? dv / sv : 0.0;
  c.p_l1 = sp > 0 ? dp / sp : 0.0;
  return c;
}

std::string sedov_comparison_table(const SedovComparison& c) {
  std::ostringstream os;
  char line[512];
  std::snprintf(line, sizeof line, "Sedov-Taylor blast wave, %dD, t = %.6g, N = %zu, gamma = %.6g, E = %.6g, rho0 = %.6g\n", c.dimension,
                c.time, c.particles, c.gamma, c.energy, c.rho0);
  os << line;
  std::snprintf(line, sizeof line, "shock radius (analytic): %.5f; densest shell at r = %.5f (%.4f of it), mean density %.4f (jump %.4f)\n",
                c.shock_radius, c.peak_radius, c.shock_radius > 0 ? c.peak_radius / c.shock_radius : 0.0, c.peak_density,
                (c.gamma + 1) / (c.gamma - 1));
  os << line;
  std::snprintf(line, sizeof line, "L1 of the particles against the solution at their radii, r < %.4f: density %.4f, radial velocity %.4f, pressure %.4f\n",
                c.bins.empty() ? 0.0 : c.bins.back().r_hi, c.rho_l1, c.vr_l1, c.p_l1);
  os << line;
  std::snprintf(line, sizeof line, "energy budget: (kinetic + internal) / (blast + ambient) - 1 = %.2e\n",
                c.total_energy / c.initial_energy - 1.0);
  os << line;
  os << "#   r_lo        r_hi      count   rho           rho_ana       v_r           v_r_ana       P             P_ana\n";
  for (const SedovBin& b : c.bins) {
    if (b.count == 0) continue;
    std::snprintf(line, sizeof line, "%11.5g %11.5g %7zu %13.5e %13.5e %13.5e %13.5e %13.5e %13.5e\n", b.r_lo, b.r_hi, b.count, b.rho,
                  b.rho_ana, b.vr, b.vr_ana, b.p, b.p_ana);
    os << line;
  }
  return os.str();
}

std::string sedov_comparison_json(const SedovComparison& c) {
  std::ostringstream os;
  os.precision(12);
  os << "{\n  \"problem\": \"sedov\",\n  \"time\": " << c.time << ",\n  \"dimension\": " << c.dimension << ",\n  \"particles\": " << c.particles
     << ",\n  \"gamma\": " << c.gamma << ",\n  \"energy\": " << c.energy << ",\n  \"rho0\": " << c.rho0 << ",\n  \"shock_radius\": "
     << c.shock_radius << ",\n  \"peak_radius\": " << c.peak_radius << ",\n  \"peak_density\": " << c.peak_density << ",\n  \"rho_l1\": "
     << c.rho_l1 << ",\n  \"vr_l1\": " << c.vr_l1 << ",\n  \"p_l1\": " << c.p_l1 << ",\n  \"total_energy\": " << c.total_energy
     << ",\n  \"initial_energy\": " << c.initial_energy << ",\n  \"bins\": [";
  for (const SedovBin& b : c.bins)
    os << (&b == &c.bins.front() ? "\n" : ",\n") << "    {\"r_lo\": " << b.r_lo << ", \"r_hi\": " << b.r_hi << ", \"count\": " << b.count
       << ", \"rho\": " << b.rho << ", \"rho_ana\": " << b.rho_ana << ", \"vr\": " << b.vr << ", \"vr_ana\": " << b.vr_ana
       << ", \"p\": " << b.p << ", \"p_ana\": " << b.p_ana << "}";
  os << "\n  ]\n}\n";
  return os.str();
}

template SedovComparison compare_sedov<2>(const Particles<2>&, const SnapshotMeta&, int);
template SedovComparison compare_sedov<3>(const Particles<3>&, const SnapshotMeta&, int);

}  // namespace sphdisk
