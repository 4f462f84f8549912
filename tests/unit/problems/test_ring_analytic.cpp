// Unit tests for the analytic viscous-ring solution (P98 eqs. 10-12, docs/physics.md section 4).

#include "problems/ring_analytic.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

namespace sphdisk {
namespace {

double rel_err(double value, double ref) { return std::abs(value - ref) / std::abs(ref); }

struct BesselRef {
  double nu;
  double z;
  double value;  // e^{-z} I_nu(z)
};

// Reference values of e^{-z} I_nu(z), produced with Debian's python3-mpmath 1.2.1 at 50 decimal
// digits, evaluated at exactly the double that each z literal denotes:
//   mp.mp.dps = 50; z = mp.mpf(float(zz)); mp.besseli(nu, z) * mp.exp(-z)
// (nu exact rationals). scipy 1.10.1's scipy.special.ive was NOT used as reference: it is off by
// up to 5.9e-14 relative here (nu = -3/4, z = 20), worse than this code.
constexpr BesselRef kBesselRefs[] = {
    {0.25, 1e-6, 0.029337356821495669025},
    {0.25, 1e-4, 0.092763684211191006173},
    {0.25, 0.01, 0.29046055201928833815},
    {0.25, 0.5, 0.49715860440173415772},
    {0.25, 1.0, 0.41344199850978711202},
    {0.25, 5.0, 0.18223762203904338023},
    {0.25, 20.0, 0.089636433474678664571},
    {0.25, 24.9, 0.080256427420518018792},
    {0.25, 25.0, 0.080094495858064874067},
    {0.25, 25.1, 0.079933540712825614676},
    {0.25, 100.0, 0.039931835556842864589},
    {0.25, 1e3, 0.012616845975937635407},
    {0.25, 1e4, 3.9894602068986837446e-3},
    {0.25, 1e5, 1.2615674437349177789e-3},
    {-0.75, 1e-6, 1.4668678410759570119e+4},
    {-0.75, 1e-4, 463.81842476650237379},
    {-0.75, 0.01, 14.52418943284513457},
    {-0.75, 0.5, 0.59444660966131437972},
    {-0.75, 1.0, 0.35900160431595622589},
    {-0.75, 5.0, 0.17223406184215171492},
    {-0.75, 20.0, 0.088493828203798486484},
    {-0.75, 24.9, 0.07943798420337521204},
    {-0.75, 25.0, 0.07928102368528623109},
    {-0.75, 25.1, 0.079124989451605920706},
    {-0.75, 100.0, 0.039831627804249074381},
    {-0.75, 1e3, 0.012613690580429677975},
    {-0.75, 1e4, 3.9893604666530182638e-3},
    {-0.75, 1e5, 1.2615642898044811285e-3},
    {0.0, 1e-6, 0.99999900000074999958},
    {0.0, 1e-4, 0.99990000749958335156},
    {0.0, 0.01, 0.9900745851497074988},
    {0.0, 0.5, 0.64503527044915006811},
    {0.0, 1.0, 0.4657596075936404365},
    {0.0, 5.0, 0.18354081260932835307},
    {0.0, 20.0, 0.089780311884826021596},
    {0.0, 24.9, 0.080359332611532213624},
    {0.0, 25.0, 0.080196773547436708422},
    {0.0, 25.1, 0.080035197254296236447},
    {0.0, 100.0, 0.039944379299096682648},
    {0.0, 1e3, 0.012617240455891256586},
    {0.0, 1e4, 3.9894726746047321064e-3},
    {0.0, 1e5, 1.2615678379767767669e-3},
    {1.0, 1e-6, 4.9999950000031247723e-7},
    {1.0, 1e-4, 4.9995000312485419609e-5},
    {1.0, 0.01, 4.9503110471182757076e-3},
    {1.0, 0.5, 0.15642080318487169714},
    {1.0, 1.0, 0.20791041534970844887},
    {1.0, 5.0, 0.16397226694454235693},
    {1.0, 20.0, 0.087506222183288665356},
    {1.0, 24.9, 0.0787287948821031292},
    {1.0, 25.0, 0.078576113319292772028},
    {1.0, 25.1, 0.078424315178368413882},
    {1.0, 100.0, 0.039744153025130252674},
    {1.0, 1e3, 0.01261093025692862947},
    {1.0, 1e4, 3.9892731959836622645e-3},
    {1.0, 1e5, 1.2615615301218171273e-3},
    {2.5, 1e-6, 5.3192250861250693106e-17},
    {2.5, 1e-4, 5.3186985127062369746e-12},
    {2.5, 0.01, 5.2663407950484642876e-7},
    {2.5, 0.5, 5.805859338644326904e-3},
    {2.5, 1.0, 0.021005514809116314286},
    {2.5, 5.0, 0.092760522193099624674},
    {2.5, 20.0, 0.076494321480050061097},
    {2.5, 24.9, 0.070703003727340598223},
    {2.5, 25.0, 0.070596825939837526688},
    {2.5, 25.1, 0.070491084755641848019},
    {2.5, 100.0, 0.038709369467351012741},
    {2.5, 1e3, 0.012577853469258328143},
    {2.5, 1e4, 3.9882260968558066018e-3},
    {2.5, 1e5, 1.2615284144007196e-3},
};

TEST(ScaledBesselI, MatchesMpmathReferences) {
  double worst = 0.0;
  for (const BesselRef& ref : kBesselRefs) {
    const double value = scaled_bessel_i(ref.nu, ref.z);
    const double err = rel_err(value, ref.value);
    worst = std::max(worst, err);
    EXPECT_LE(err, 1e-12) << "nu = " << ref.nu << ", z = " << ref.z << ": got " << value
                          << ", expected " << ref.value;
  }
  std::ostringstream worst_text;
  worst_text << std::scientific << worst;
  RecordProperty("max_rel_err_vs_mpmath", worst_text.str());
}

// Half-integer orders have closed forms: Ĩ_{1/2}(z) = (1 - e^{-2z})/sqrt(2 pi z),
// Ĩ_{-1/2}(z) = (1 + e^{-2z})/sqrt(2 pi z). Independent check over a dense z range, both branches.
TEST(ScaledBesselI, MatchesClosedFormForHalfIntegerOrders) {
  for (double z = 1e-6; z < 2e5; z *= 1.07) {
    const double s = 1.0 / std::sqrt(2.0 * std::numbers::pi * z);
    const double e = std::exp(-2.0 * z);
    EXPECT_LE(rel_err(scaled_bessel_i(0.5, z), -std::expm1(-2.0 * z) * s), 1e-13) << "z = " << z;
    EXPECT_LE(rel_err(scaled_bessel_i(-0.5, z), (1.0 + e) * s), 1e-13) << "z = " << z;
  }
}

TEST(ScaledBesselI, ContinuousAcrossSeriesAsymptoticSwitch) {
  const double below = std::nextafter(kScaledBesselSwitch, 0.0);  // last z on the series branch
  const double above = std::nextafter(kScaledBesselSwitch, 100.0);
  for (double nu : {0.25, -0.75, 0.0, 1.0, 2.5, -1.5, 3.0}) {
    const double a = scaled_bessel_i(nu, below);
    const double b = scaled_bessel_i(nu, kScaledBesselSwitch);  // first z on the Hankel branch
    const double c = scaled_bessel_i(nu, above);
    EXPECT_LE(rel_err(a, b), 1e-14) << "nu = " << nu;
    EXPECT_LE(rel_err(c, b), 1e-14) << "nu = " << nu;
  }
}

TEST(ScaledBesselI, EdgeCases) {
  EXPECT_EQ(scaled_bessel_i(0.0, 0.0), 1.0);
  EXPECT_EQ(scaled_bessel_i(0.25, 0.0), 0.0);
  EXPECT_EQ(scaled_bessel_i(-0.75, 0.0), std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(scaled_bessel_i(0.25, -1.0)));
  EXPECT_TRUE(std::isnan(scaled_bessel_i(0.25, std::numeric_limits<double>::quiet_NaN())));
  // I_{-n} = I_n for integer n (the series would hit a pole of Gamma otherwise).
  for (double z : {1e-3, 0.7, 12.0, 40.0}) {
    EXPECT_DOUBLE_EQ(scaled_bessel_i(-1.0, z), scaled_bessel_i(1.0, z));
    EXPECT_DOUBLE_EQ(scaled_bessel_i(-2.0, z), scaled_bessel_i(2.0, z));
  }
  // No overflow far beyond where I_nu itself overflows (z ~ 710).
  const double big = scaled_bessel_i(0.25, 1e7);
  EXPECT_TRUE(std::isfinite(big));
  EXPECT_LE(rel_err(big, 1.0 / std::sqrt(2.0 * std::numbers::pi * 1e7)), 1e-7);
}

// docs/physics.md sec. 4: nu = 4.778e-5 in code units; t(tau = 0.018) = 31.39, t(0.09) = 157.0.
TEST(RingSolution, TimeTauConversion) {
  const RingSolution ring{1e-10, 1.0, 4.778e-5};
  EXPECT_NEAR(ring.time_of_tau(0.018), 31.39, 0.005);
  EXPECT_NEAR(ring.time_of_tau(0.09), 157.0, 0.05);
  EXPECT_NEAR(ring.time_of_tau(0.126), 219.8, 0.05);
  const RingSolution other{2.0, 3.7, 1.3e-3};
  for (double tau : {0.018, 0.09, 0.5}) {
    EXPECT_LE(rel_err(other.tau_of_time(other.time_of_tau(tau)), tau), 1e-15);
  }
  EXPECT_LE(rel_err(other.tau_of_time(10.0), 12.0 * 1.3e-3 * 10.0 / (3.7 * 3.7)), 1e-15);
}

struct SigmaRef {
  double r, tau, m, r0, sigma;
};

// Eq. 11 evaluated with python3-mpmath 1.2.1 at 40 digits:
//   m/(pi r0^2 tau) x^{-1/4} exp(-(1+x^2)/tau) besseli(1/4, 2x/tau),  x = r/r0
// (r = 0: the limit m/(pi r0^2 tau) tau^{-1/4} e^{-1/tau}/Gamma(5/4)). scipy's ive-based formula
// agrees with these to <= 1e-14 relative.
constexpr SigmaRef kSigmaRefs[] = {
    {1.0, 0.018, 1.0, 1.0, 0.669849200254659},
    {0.7, 0.09, 1.0, 1.0, 0.14478170230505624},
    {1.3, 0.126, 1.0, 1.0, 0.10219168963754183},
    {0.05, 0.09, 1.0, 1.0, 0.0001309334352469032},
    {0.0, 0.09, 1.0, 1.0, 0.00010647108098623062},
    {1e-6, 0.09, 1.0, 1.0, 0.00010647108099556327},
    {2.0, 0.126, 1.0, 1.0, 5.392736988250411e-05},
    {0.5, 0.018, 1.0, 1.0, 1.047739287277059e-06},
    {3.33, 0.09, 2.5e-10, 3.7, 5.3187940808085965e-12},
    {4.07, 0.018, 2.5e-10, 3.7, 6.533723855261211e-12},
    {0.37, 0.126, 2.5e-10, 3.7, 4.454320330340757e-14},
};

TEST(RingSolution, SurfaceDensityMatchesMpmath) {
  for (const SigmaRef& ref : kSigmaRefs) {
    const RingSolution ring{ref.m, ref.r0, 1.0};
    EXPECT_LE(rel_err(ring.surface_density(ref.r, ref.tau), ref.sigma), 1e-12)
        << "r = " << ref.r << ", tau = " << ref.tau << ", r0 = " << ref.r0;
  }
}

TEST(RingSolution, SurfaceDensityFiniteAtOrigin) {
  const RingSolution ring{1.0, 1.0, 1.0};
  const double at0 = ring.surface_density(0.0, 0.09);
  EXPECT_TRUE(std::isfinite(at0));
  EXPECT_LE(rel_err(ring.surface_density(1e-300, 0.09), at0), 1e-15);
  EXPECT_LE(rel_err(ring.surface_density(1e-9, 0.09), at0), 1e-12);
  EXPECT_TRUE(std::isnan(ring.surface_density(-1.0, 0.09)));
  EXPECT_TRUE(std::isnan(ring.surface_density(1.0, 0.0)));
}

// Eq. 11 is linear in m; in units of r0 it scales as 1/r0^2 (Sigma(r, r0) = Sigma_1(r/r0) / r0^2).
TEST(RingSolution, SurfaceDensityScaling) {
  const RingSolution unit{1.0, 1.0, 1.0};
  const RingSolution scaled{3e-10, 2.5, 7.0};
  for (double x : {0.0, 0.2, 0.95, 1.0, 1.4}) {
    for (double tau : {0.018, 0.09}) {
      EXPECT_LE(rel_err(scaled.surface_density(2.5 * x, tau),
                        3e-10 * unit.surface_density(x, tau) / (2.5 * 2.5)),
                1e-14);
    }
  }
}

// The branch switch at z = 2x/tau = 25 must not show in Sigma or v_r.
TEST(RingSolution, ContinuousAcrossBesselSwitch) {
  const RingSolution ring{1.0, 1.0, 1.0};
  for (double tau : {0.018, 0.09, 0.126}) {
    const double x_switch = kScaledBesselSwitch * tau / 2.0;
    const double lo = x_switch * (1.0 - 1e-14);
    const double hi = x_switch * (1.0 + 1e-14);
    EXPECT_LE(rel_err(ring.surface_density(lo, tau), ring.surface_density(hi, tau)), 1e-12);
    EXPECT_LE(rel_err(ring.radial_velocity(lo, tau), ring.radial_velocity(hi, tau)), 1e-12);
  }
}

// Facts quoted in docs/physics.md sec. 4 (tau = 0.09, r0 = 1), checked to the digits given.
TEST(RingSolution, RadialVelocityMatchesDesignNotes) {
  const RingSolution ring{1.0, 1.0, 1.0};
  EXPECT_NEAR(ring.radial_velocity(0.2, 0.09), -49.0, 0.5);
  EXPECT_NEAR(ring.radial_velocity(0.8, 0.09), -12.4, 0.05);
  EXPECT_NEAR(ring.radial_velocity(1.0, 0.09), 0.76, 0.005);
  EXPECT_NEAR(ring.radial_velocity(1.5, 0.09), 34.0, 0.5);
  // v_r changes sign near x = 0.99 (mpmath root: 0.98841427611932...).
  double a = 0.9;
  double b = 1.1;
  ASSERT_LT(ring.radial_velocity(a, 0.09), 0.0);
  ASSERT_GT(ring.radial_velocity(b, 0.09), 0.0);
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (a + b);
    (ring.radial_velocity(mid, 0.09) < 0.0 ? a : b) = mid;
  }
  EXPECT_NEAR(a, 0.99, 0.005);
  EXPECT_NEAR(a, 0.98841427611932028, 1e-12);
}

struct VrRef {
  double r, tau, nu, r0, vr;
};

// Eq. 12 with python3-mpmath 1.2.1 at 40 digits:
//   6 nu/(r0 tau) (x - besseli(-3/4, z)/besseli(1/4, z)),  z = 2x/tau.
constexpr VrRef kVrRefs[] = {
    {0.2, 0.09, 1.0, 1.0, -49.155426840769046},
    {0.8, 0.09, 1.0, 1.0, -12.374835603694626},
    {1.0, 0.09, 1.0, 1.0, 0.763269595279804},
    {1.5, 0.09, 1.0, 1.0, 33.83913543949213},
    {0.05, 0.018, 1.0, 1.0, -300.3874233267909},
    {1.02, 0.018, 1.0, 1.0, 7.404415508527674},
    {2.22, 0.126, 4.778e-5, 3.7, -0.0002291133123526693},
    {1e-3, 0.126, 4.778e-5, 3.7, -0.07167088902077667},
};

TEST(RingSolution, RadialVelocityMatchesMpmath) {
  for (const VrRef& ref : kVrRefs) {
    const RingSolution ring{1.0, ref.r0, ref.nu};
    EXPECT_LE(rel_err(ring.radial_velocity(ref.r, ref.tau), ref.vr), 1e-12)
        << "r = " << ref.r << ", tau = " << ref.tau;
  }
}

// Near the origin eq. 12 tends to the steady constant-nu inflow v_r = -3 nu/(2 r); -inf at r = 0.
TEST(RingSolution, RadialVelocityNearOrigin) {
  const RingSolution ring{1.0, 2.0, 3e-4};
  EXPECT_EQ(ring.radial_velocity(0.0, 0.09), -std::numeric_limits<double>::infinity());
  for (double r : {1e-8, 1e-6}) {
    EXPECT_LE(rel_err(ring.radial_velocity(r, 0.09), -1.5 * 3e-4 / r), 1e-6) << "r = " << r;
  }
}

// Eqs. 11 and 12 must satisfy the continuity equation dSigma/dt + (1/r) d(r Sigma v_r)/dr = 0,
// with dt = r0^2 dtau / (12 nu). Central differences; an independent check of eq. 12 vs eq. 11.
TEST(RingSolution, SatisfiesContinuityEquation) {
  const RingSolution ring{2.0, 1.7, 3e-3};
  const double r0 = ring.ring_radius;
  for (double tau : {0.018, 0.09, 0.126}) {
    const double sigma_scale = ring.surface_density(r0, tau);
    for (double x : {0.3, 0.7, 0.95, 1.0, 1.05, 1.3, 1.8}) {
      const double r = x * r0;
      const double dtau = 1e-5 * tau;
      const double dr = 1e-5 * r0;
      const double dsigma_dt = (ring.surface_density(r, tau + dtau) - ring.surface_density(r, tau - dtau)) /
                               (2.0 * dtau) * 12.0 * ring.viscosity / (r0 * r0);
      auto flux = [&](double rr) { return rr * ring.surface_density(rr, tau) * ring.radial_velocity(rr, tau); };
      const double div = (flux(r + dr) - flux(r - dr)) / (2.0 * dr) / r;
      const double scale = sigma_scale * 12.0 * ring.viscosity / (r0 * r0 * tau);
      EXPECT_LE(std::abs(dsigma_dt + div), 1e-6 * scale) << "x = " << x << ", tau = " << tau;
    }
  }
}

// Regularized Q(1/4, 1/tau) from python3-mpmath 1.2.1 (40 digits):
//   mp.gammainc(mpf(1)/4, 1/tau, mp.inf, regularized=True); scipy.special.gammaincc agrees.
TEST(RingSolution, AccretedMassMatchesIncompleteGamma) {
  const RingSolution ring{1.0, 1.0, 1.0};
  EXPECT_LE(rel_err(ring.accreted_mass(0.018), 9.97419055223984e-27), 1e-12);
  EXPECT_LE(rel_err(ring.accreted_mass(0.09), 6.374668602242496e-07), 1e-12);
  EXPECT_LE(rel_err(ring.accreted_mass(0.126), 1.9209723712783575e-05), 1e-12);
  EXPECT_LE(rel_err(ring.accreted_mass(0.5), 0.017286011859516774), 1e-12);
  EXPECT_LE(rel_err(ring.accreted_mass(2.0), 0.15351359580832247), 1e-12);  // series branch
  const RingSolution heavy{4.2e-9, 5.0, 1e-3};
  EXPECT_LE(rel_err(heavy.accreted_mass(0.126), 4.2e-9 * 1.9209723712783575e-05), 1e-12);
}

// d(accreted)/dt equals the inflow -2 pi r Sigma v_r at r -> 0 (consistency of eqs. 11-12 with
// accreted_mass).
TEST(RingSolution, AccretionRateEqualsInflowAtOrigin) {
  const RingSolution ring{1.5, 2.0, 2e-3};
  for (double tau : {0.09, 0.126, 0.3}) {
    const double h = 1e-4 * tau;
    const double dmdtau = (ring.accreted_mass(tau + h) - ring.accreted_mass(tau - h)) / (2.0 * h);
    const double dmdt = dmdtau * 12.0 * ring.viscosity / (ring.ring_radius * ring.ring_radius);
    const double r = 1e-7;
    const double inflow = -2.0 * std::numbers::pi * r * ring.surface_density(r, tau) * ring.radial_velocity(r, tau);
    EXPECT_LE(rel_err(dmdt, inflow), 1e-6) << "tau = " << tau;
  }
}

// Mass conservation. NOTE: the disc mass alone is NOT conserved: the I_{1/4} solution (zero torque
// at r = 0) drains mass into the centre, m Q(1/4, 1/tau) = 6.4e-7 m at tau = 0.09 and 1.9e-5 m at
// tau = 0.126. Disc + accreted is conserved; at tau = 0.018 the drain is 1e-26 m.
TEST(RingSolution, MassConservation) {
  const RingSolution rings[] = {{1.0, 1.0, 1.0}, {1e-10, 1.0, 4.778e-5}, {3.3, 0.4, 0.2}, {7e-4, 12.0, 5e-6}};
  for (const RingSolution& ring : rings) {
    const double m = ring.disc_mass;
    for (double tau : {0.018, 0.09, 0.126}) {
      const double disc = ring.enclosed_mass(50.0 * ring.ring_radius, tau);
      EXPECT_NEAR((disc + ring.accreted_mass(tau)) / m, 1.0, 1e-9) << "tau = " << tau;
      EXPECT_NEAR(ring.enclosed_mass(1e6 * ring.ring_radius, tau) / m, disc / m, 1e-12);
    }
    EXPECT_NEAR(ring.enclosed_mass(50.0 * ring.ring_radius, 0.018) / m, 1.0, 1e-9);
    // The drain is real: at tau = 0.126 the disc has lost 1.92e-5 of its mass.
    EXPECT_NEAR(1.0 - ring.enclosed_mass(50.0 * ring.ring_radius, 0.126) / m, 1.9209723712783575e-05, 1e-12);
  }
}

// docs/physics.md sec. 4: mass inside r < 0.05 is 9e-7 (tau = 0.09) and 1.4e-5 (tau = 0.126), times m.
TEST(RingSolution, InnerMassMatchesDesignNotes) {
  const RingSolution ring{1e-10, 1.0, 4.778e-5};
  EXPECT_NEAR(ring.enclosed_mass(0.05, 0.09) / ring.disc_mass, 9e-7, 0.5e-7);
  EXPECT_NEAR(ring.enclosed_mass(0.05, 0.126) / ring.disc_mass, 1.4e-5, 0.05e-5);
}

struct MassRef {
  double r, tau, m, r0, mass;
};

// 2 m / tau * integral_0^{r/r0} x S(x) dx with mpmath.quad at 40 digits (S as in kSigmaRefs).
constexpr MassRef kMassRefs[] = {
    {0.05, 0.09, 1.0, 1.0, 9.30794212222741e-07},
    {0.05, 0.126, 1.0, 1.0, 1.3839502167683275e-05},
    {1.0, 0.018, 1.0, 1.0, 0.4905248760463816},
    {0.8, 0.09, 1.0, 1.0, 0.15803593232695134},
    {1.2, 0.126, 1.0, 1.0, 0.7700594247261073},
    {3.7, 0.09, 2.5e-10, 3.7, 1.1967233364021606e-10},
    {0.185, 0.126, 2.5e-10, 3.7, 3.4598755419208185e-15},
};

TEST(RingSolution, EnclosedMassMatchesMpmath) {
  for (const MassRef& ref : kMassRefs) {
    const RingSolution ring{ref.m, ref.r0, 1.0};
    const double mass = ring.enclosed_mass(ref.r, ref.tau);
    EXPECT_LE(std::abs(mass - ref.mass), 1e-10 * ref.m) << "r = " << ref.r << ", tau = " << ref.tau;
    EXPECT_LE(rel_err(mass, ref.mass), 1e-10) << "r = " << ref.r << ", tau = " << ref.tau;
  }
  const RingSolution ring{1.0, 1.0, 1.0};
  EXPECT_EQ(ring.enclosed_mass(0.0, 0.09), 0.0);
}

struct AnnulusRef {
  double r_in, r_out, tau, m, r0, mean;
};

// (integral_{r_in}^{r_out} 2 pi r Sigma dr) / (pi (r_out^2 - r_in^2)), mpmath.quad at 40 digits.
constexpr AnnulusRef kAnnulusRefs[] = {
    {0.85, 0.89, 0.018, 1.0, 1.0, 0.2928527437568682},
    {0.05, 0.09, 0.09, 1.0, 1.0, 0.00016161220485620196},
    {0.05, 0.09, 0.018, 1.0, 1.0, 1.2995933876835752e-20},  // far tail: relative accuracy kept
    {4.4, 4.5, 0.126, 3e-3, 3.7, 3.500549910950625e-05},
};

TEST(RingSolution, AnnulusMeanMatchesMpmath) {
  for (const AnnulusRef& ref : kAnnulusRefs) {
    const RingSolution ring{ref.m, ref.r0, 1.0};
    EXPECT_LE(rel_err(ring.annulus_mean_surface_density(ref.r_in, ref.r_out, ref.tau), ref.mean), 1e-11)
        << "[" << ref.r_in << ", " << ref.r_out << "], tau = " << ref.tau;
  }
}

// Paper Fig. 8 binning (50 bins over 0.05 <= r <= 2.05): the bin masses add up to the enclosed
// mass difference, and a very narrow annulus tends to the local Sigma.
TEST(RingSolution, AnnulusMeanConsistency) {
  const RingSolution ring{1e-10, 1.0, 4.778e-5};
  for (double tau : {0.018, 0.09, 0.126}) {
    double binned_mass = 0.0;
    for (int i = 0; i < 50; ++i) {
      const double a = 0.05 + 0.04 * i;
      const double b = a + 0.04;
      binned_mass += ring.annulus_mean_surface_density(a, b, tau) * std::numbers::pi * (b * b - a * a);
    }
    const double direct = ring.enclosed_mass(2.05, tau) - ring.enclosed_mass(0.05, tau);
    EXPECT_LE(rel_err(binned_mass, direct), 1e-11) << "tau = " << tau;
    for (double r : {0.6, 1.0, 1.3}) {
      EXPECT_LE(rel_err(ring.annulus_mean_surface_density(r - 1e-5, r + 1e-5, tau), ring.surface_density(r, tau)), 1e-7);
    }
    EXPECT_EQ(ring.annulus_mean_surface_density(1.0, 1.0, tau), ring.surface_density(1.0, tau));
  }
  EXPECT_TRUE(std::isnan(ring.annulus_mean_surface_density(1.0, 0.5, 0.09)));
}

}  // namespace
}  // namespace sphdisk
