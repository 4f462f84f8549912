#include "app/disc_profiles.hpp"
#include "app/radial_motion.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <sstream>

#include "core/error.hpp"
#include "core/units.hpp"

namespace sphdisk {

namespace {

// G M of the point mass in the file's units: from physics.central_mass (solar masses) and /Units
// where both are recorded (sphdisk's own files: 1), else 1 (code units with G = M = 1 assumed).
double point_mass_gm(const SnapshotMeta& meta) {
  const std::string mass = meta.parameter("physics.central_mass");
  const UnitSystem& u = meta.units;
  const bool units_recorded = !(u.length_cm == 1 && u.mass_g == 1 && u.time_s == 1);
  if (mass.empty() || !units_recorded) return 1.0;
  return cgs::G * std::atof(mass.c_str()) * cgs::solar_mass * u.time_s * u.time_s / (u.length_cm * u.length_cm * u.length_cm);
}

}  // namespace

bool is_ring_snapshot(const SnapshotMeta& meta) {
  if (!meta.problem.empty()) return meta.problem == "ring";
  // Without Problem: the ring only where the file has its Header attributes (an sphdisk ring's).
  if (!(meta.tau > 0 && meta.viscosity > 0 && meta.disc_mass > 0)) return false;
  const std::string ic = meta.parameter("problem.initial_conditions");
  return ic.empty() || ic == "\"\"";
}

DiscProfiles disc_profiles(const Particles<2>& p, const SnapshotMeta& meta, int nbins, double r_min, double r_max,
                           const std::vector<double>* z) {
  if (p.size() == 0) throw UserError("the snapshot holds no particles: no profiles to form");
  if (nbins < 1) throw UserError("the number of radial bins must be at least 1");
  DiscProfiles d;
  d.time = meta.time;
  d.particles = p.size();
  d.accreted_mass = meta.accreted_mass;
  d.initial_mass = meta.disc_mass;
  d.gm = point_mass_gm(meta);
  d.heights = z != nullptr;
  if (!(r_max > r_min)) {
    r_min = r_max = norm(p.pos[0]);
    for (std::size_t i = 0; i < p.size(); ++i) r_min = std::min(r_min, norm(p.pos[i])), r_max = std::max(r_max, norm(p.pos[i]));
    r_max = std::nextafter(r_max, 2 * r_max + 1);  // the outermost particle inside the last bin
  }
  const double width = (r_max - r_min) / nbins;
  d.bins.resize(static_cast<std::size_t>(nbins));
  for (int b = 0; b < nbins; ++b) d.bins[static_cast<std::size_t>(b)].r_lo = r_min + b * width, d.bins[static_cast<std::size_t>(b)].r_hi = r_min + (b + 1) * width;
  std::vector<double> bin_mass(d.bins.size(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    d.mass += p.mass[i];
    const double r = norm(p.pos[i]);
    const double fb = (r - r_min) / width;
    if (!(fb >= 0 && fb < nbins)) continue;
    const auto b = static_cast<std::size_t>(fb);
    const double m = p.mass[i];
    const RadialMotion motion = radial_motion(p, i, d.gm);
    DiscBin& bin = d.bins[b];
    ++bin.count;
    bin_mass[b] += m;
    bin.vr += m * motion.vr;
    bin.vr_drift += m * motion.drift;
    bin.j += m * motion.j;
    if (z) bin.z_rms += m * (*z)[i] * (*z)[i];
  }
  for (std::size_t b = 0; b < d.bins.size(); ++b) {
    DiscBin& bin = d.bins[b];
    bin.sigma = bin_mass[b] / (std::numbers::pi * (bin.r_hi * bin.r_hi - bin.r_lo * bin.r_lo));
    if (bin.count == 0) continue;
    bin.vr /= bin_mass[b];
    bin.vr_drift /= bin_mass[b];
    bin.j /= bin_mass[b];
    bin.z_rms = std::sqrt(bin.z_rms / bin_mass[b]);
    bin.mdot = -std::numbers::pi * (bin.r_lo + bin.r_hi) * bin.sigma * bin.vr;
  }
  return d;
}

std::string disc_profiles_table(const DiscProfiles& d) {
  std::ostringstream os;
  char line[512];
  std::snprintf(line, sizeof line, "# t = %.6g  N = %zu  mass = %.6e  accreted = %.6e  (G M = %.6g; file units)\n", d.time,
                d.particles, d.mass, d.accreted_mass, d.gm);
  os << line;
  if (d.initial_mass > 0) {
    std::snprintf(line, sizeof line, "mass budget: (particles + accreted) / initial disc mass - 1 = %.2e\n",
                  (d.mass + d.accreted_mass) / d.initial_mass - 1.0);
    os << line;
  }
  os << "#   r_lo        r_hi      count   Sigma         v_r           v_r_drift     j             Mdot_in"
     << (d.heights ? "       z_rms         z_rms/R\n" : "\n");
  for (const DiscBin& b : d.bins) {
    if (b.count == 0) continue;
    std::snprintf(line, sizeof line, "%11.5g %11.5g %7zu %13.5e %13.5e %13.5e %13.5e %13.5e", b.r_lo, b.r_hi, b.count,
                  b.sigma, b.vr, b.vr_drift, b.j, b.mdot);
    os << line;
    if (d.heights) {
      std::snprintf(line, sizeof line, " %13.5e %13.5e", b.z_rms, 2.0 * b.z_rms / (b.r_lo + b.r_hi));
      os << line;
    }
    os << "\n";
  }
  return os.str();
}

std::string disc_profiles_json(const DiscProfiles& d) {
  std::ostringstream os;
  os.precision(17);
  os << "{\n  \"problem\": \"disc\",\n  \"time\": " << d.time << ",\n  \"particles\": " << d.particles << ",\n  \"mass\": " << d.mass
     << ",\n  \"accreted_mass\": " << d.accreted_mass << ",\n  \"initial_mass\": " << d.initial_mass << ",\n  \"gm\": " << d.gm
     << ",\n  \"bins\": [";
  bool first = true;
  for (const DiscBin& b : d.bins) {
    os << (first ? "\n" : ",\n") << "    {\"r_lo\": " << b.r_lo << ", \"r_hi\": " << b.r_hi << ", \"count\": " << b.count
       << ", \"sigma\": " << b.sigma << ", \"vr\": " << b.vr << ", \"vr_drift\": " << b.vr_drift << ", \"j\": " << b.j
       << ", \"mdot_in\": " << b.mdot;
    if (d.heights) os << ", \"z_rms\": " << b.z_rms;
    os << "}";
    first = false;
  }
  os << "\n  ]\n}\n";
  return os.str();
}

}  // namespace sphdisk
