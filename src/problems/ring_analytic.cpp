// Analytic solution of the viscously spreading ring, P98 eqs. 10-12 (docs/physics.md section 4).
//
// Everything is written in terms of the exponentially scaled Bessel function
// Ĩ_nu(z) = e^{-z} I_nu(z): I_nu itself overflows a double for z > ~710 (z = 2x/tau reaches
// 2e4 at tau = 1e-4), while Ĩ_nu ~ (2 pi z)^{-1/2} stays O(1). Eq. 11's factor
// exp(-(r0^2 + r^2)/(r0^2 tau)) I_{1/4}(z) is then rewritten exactly as
// exp(-(1-x)^2/tau) Ĩ_{1/4}(z), since (1 + x^2)/tau - 2x/tau = (1-x)^2/tau.

#include "problems/ring_analytic.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace sphdisk {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Series terms are summed until the next term is below kSeriesEps of the sum (and the term
// ratio guarantees the geometric tail is no bigger): well below double rounding.
constexpr double kSeriesEps = 1e-17;

// 1/Gamma(nu + 1) for the two orders of eqs. 11-12, hard-coded (mpmath, 40 digits) so that the
// per-particle evaluation needs no tgamma call: 1/Gamma(5/4) (nu = 1/4), 1/Gamma(1/4) (nu = -3/4).
constexpr double kInvGamma5_4 = 1.103262651320837257439782;
constexpr double kInvGamma1_4 = 0.2758156628302093143599455;

// Reduced series (z/2)^{-nu} e^{-z} I_nu(z) = e^{-z} sum_k (z^2/4)^k / (k! Gamma(k + nu + 1)),
// from the ascending series of docs/physics.md sec. 4 with the (z/2)^nu factor taken out. Taking it
// out keeps x^{-1/4} Ĩ_{1/4}(2x/tau) finite as x -> 0 (no 0 * inf) in eq. 11.
// inv_gamma = 1/Gamma(nu + 1); nu must not be a negative integer (k + nu = 0 would divide by 0).
// For z < 25 all terms for k > -nu have one sign and the sum is at most ~e^z ~ 7e10, so there is
// no cancellation and no overflow; ~60 terms at z = 25.
double reduced_series_sum(double nu, double inv_gamma, double z) {
  const double q = 0.25 * z * z;
  double term = inv_gamma;
  double sum = term;
  for (int k = 1; k < 1000; ++k) {
    const double denom = k * (k + nu);
    term *= q / denom;
    sum += term;
    // Stop only once the terms shrink by at least 2x per step (tail <= current term).
    if (denom > 2.0 * q && std::abs(term) <= kSeriesEps * std::abs(sum)) break;
  }
  return sum;
}

// Hankel asymptotic expansion (docs/physics.md sec. 4):
//   Ĩ_nu(z) ~ (2 pi z)^{-1/2} sum_k (-1)^k a_k(nu) z^{-k},
//   a_k = prod_{j=1..k} (4 nu^2 - (2j-1)^2) / (k! 8^k).
// It depends on nu only through nu^2; the difference I_{-nu} - I_nu = (2/pi) sin(nu pi) K_nu is
// O(e^{-2z}) ~ 2e-22 relative at z >= 25, far below double precision. For z >= 25 and |nu| <= 3
// the smallest term is ~e^{-2z}, so the sum is cut when terms drop below kSeriesEps (or stop
// exactly for half-integer nu, where the series terminates).
double hankel_scaled(double nu, double z) {
  const double mu = 4.0 * nu * nu;
  double term = 1.0;
  double sum = 1.0;
  for (int k = 1; k < 200; ++k) {
    const double odd = 2.0 * k - 1.0;
    const double next = -term * (mu - odd * odd) / (8.0 * k * z);
    if (std::abs(next) >= std::abs(term)) break;  // asymptotic series starts to diverge
    term = next;
    sum += term;
    if (std::abs(term) <= kSeriesEps * std::abs(sum)) break;  // also exits on term == 0
  }
  return sum / std::sqrt(2.0 * std::numbers::pi * z);
}

// Dimensionless ring profile S(x, tau) = x^{-1/4} exp(-(1-x)^2/tau) Ĩ_{1/4}(2x/tau), so that
// eq. 11 reads Sigma = m/(pi r0^2 tau) S. In the series regime x^{-1/4} (z/2)^{1/4} = tau^{-1/4}
// exactly (z/2 = x/tau), which gives the finite limit at x = 0.
double ring_shape(double x, double tau) {
  const double z = 2.0 * x / tau;
  const double gauss = std::exp(-(1.0 - x) * (1.0 - x) / tau);
  if (z < kScaledBesselSwitch) {
    const double inv_tau_quarter = 1.0 / std::sqrt(std::sqrt(tau));
    return inv_tau_quarter * gauss * std::exp(-z) * reduced_series_sum(0.25, kInvGamma5_4, z);
  }
  return gauss * hankel_scaled(0.25, z) / std::sqrt(std::sqrt(x));
}

// Gauss-Kronrod 7/15 nodes and weights (QUADPACK qk15). Nodes xgk[1], xgk[3], xgk[5], xgk[7]
// are the 7-point Gauss-Legendre nodes (with +-), weights wg.
constexpr double kXgk[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                            0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                            0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                            0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
constexpr double kWgk[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                            0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                            0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                            0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
constexpr double kWg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                           0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

// Integrand of the mass integral in x = r/r0: integral 2 pi r Sigma dr = (2 m / tau) integral x S dx.
double mass_integrand(double x, double tau) { return x * ring_shape(x, tau); }

// One GK15 panel on [a, b]: returns the Kronrod estimate, sets err = |Kronrod - Gauss|.
double gk15(double a, double b, double tau, double& err) {
  const double c = 0.5 * (a + b);
  const double h = 0.5 * (b - a);
  const double fc = mass_integrand(c, tau);
  double kron = kWgk[7] * fc;
  double gauss = kWg[3] * fc;
  for (int j = 0; j < 7; ++j) {
    const double dx = h * kXgk[j];
    const double f2 = mass_integrand(c - dx, tau) + mass_integrand(c + dx, tau);
    kron += kWgk[j] * f2;
    if (j % 2 == 1) gauss += kWg[j / 2] * f2;
  }
  err = std::abs((kron - gauss) * h);
  return kron * h;
}

// Adaptive bisection on one panel. A panel is accepted when |K - G| (the error estimate of the
// 7-point Gauss rule, very pessimistic for the 15-point Kronrod result actually used) is below
// rel_tol of the panel value or below abs_tol; the integrand is positive, so per-panel relative
// accuracy gives the same relative accuracy for the sum.
double integrate_panel(double a, double b, double tau, double abs_tol, int depth) {
  constexpr double kRelTol = 1e-13;
  double err = 0.0;
  const double val = gk15(a, b, tau, err);
  if (err <= kRelTol * std::abs(val) || err <= abs_tol || depth >= 40) return val;
  const double m = 0.5 * (a + b);
  return integrate_panel(a, m, tau, 0.5 * abs_tol, depth + 1) +
         integrate_panel(m, b, tau, 0.5 * abs_tol, depth + 1);
}

// integral_a^b x S(x, tau) dx for 0 <= a <= b. The ring is close to a Gaussian of variance
// tau/2 around x ~ 1 (docs/physics.md sec. 4), and S <= 1.11 tau^{-1/4} exp(-(1-x)^2/tau), so the part
// beyond x_hi = 1 + sqrt(60 tau) is below ~e^{-60} of the total and the upper limit is clipped
// there (unless the whole interval lies beyond it). Initial panels are at most sqrt(tau)/2 wide
// so that no GK15 panel can step over the peak; adaptive bisection does the rest (e.g. the
// structure on the scale z ~ 1, x ~ tau/2, near the origin).
double integrate_mass(double a, double b, double tau) {
  const double x_hi = 1.0 + std::sqrt(60.0 * tau);
  if (a < x_hi) b = std::min(b, x_hi);
  if (!(b > a)) return 0.0;
  const double width = 0.5 * std::sqrt(tau);
  const int n = static_cast<int>(std::clamp(std::ceil((b - a) / width), 16.0, 4096.0));
  // Absolute floor: 1e-18 of the total integral tau/2 spread over the panels, so that panels
  // where the integrand is negligible (or underflows) do not force endless refinement.
  const double abs_tol = 1e-18 * 0.5 * tau / n;
  const double step = (b - a) / n;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double lo = a + i * step;
    const double hi = (i == n - 1) ? b : a + (i + 1) * step;
    sum += integrate_panel(lo, hi, tau, abs_tol, 0);
  }
  return sum;
}

// Regularized upper incomplete gamma function Q(a, x) = Gamma(a, x)/Gamma(a) for a > 0, x > 0,
// given inv_gamma_a = 1/Gamma(a). Continued fraction (modified Lentz) for x >= a + 1, where it
// converges fast and keeps full relative accuracy for tiny Q; ascending series for P = 1 - Q
// otherwise (Q >= ~0.3 there, so 1 - P loses nothing).
double regularized_gamma_q(double a, double inv_gamma_a, double x) {
  constexpr double kEps = 1e-17;
  constexpr double kTinyLentz = 1e-300;
  const double prefactor = std::exp(-x + a * std::log(x)) * inv_gamma_a;  // e^-x x^a / Gamma(a)
  if (x >= a + 1.0) {
    double b = x + 1.0 - a;
    double c = 1.0 / kTinyLentz;
    double d = 1.0 / b;
    double h = d;
    for (int i = 1; i < 1000; ++i) {
      const double an = -i * (i - a);
      b += 2.0;
      d = an * d + b;
      if (std::abs(d) < kTinyLentz) d = kTinyLentz;
      c = b + an / c;
      if (std::abs(c) < kTinyLentz) c = kTinyLentz;
      d = 1.0 / d;
      const double delta = d * c;
      h *= delta;
      if (std::abs(delta - 1.0) < kEps) break;
    }
    return prefactor * h;
  }
  double ap = a;
  double term = 1.0 / a;
  double sum = term;
  for (int n = 1; n < 1000; ++n) {
    ap += 1.0;
    term *= x / ap;
    sum += term;
    if (std::abs(term) < kEps * std::abs(sum)) break;
  }
  return 1.0 - prefactor * sum;
}

}  // namespace

double scaled_bessel_i(double nu, double z) {
  if (std::isnan(nu) || std::isnan(z) || z < 0.0) return kNaN;
  // I_{-n} = I_n for integer n; also avoids the poles of Gamma(k + nu + 1) in the series.
  if (nu < 0.0 && nu == std::floor(nu)) nu = -nu;
  if (z == 0.0) {
    if (nu == 0.0) return 1.0;
    if (nu > 0.0) return 0.0;
    return std::copysign(kInf, std::tgamma(nu + 1.0));  // I_nu ~ (z/2)^nu / Gamma(nu + 1)
  }
  if (std::isinf(z)) return 0.0;  // Ĩ_nu ~ (2 pi z)^{-1/2} -> 0
  if (z < kScaledBesselSwitch) {
    return std::pow(0.5 * z, nu) * std::exp(-z) *
           reduced_series_sum(nu, 1.0 / std::tgamma(nu + 1.0), z);
  }
  return hankel_scaled(nu, z);
}

double RingSolution::tau_of_time(double t) const {
  return 12.0 * viscosity * t / (ring_radius * ring_radius);  // P98, below eq. 12
}

double RingSolution::time_of_tau(double tau) const {
  return tau * ring_radius * ring_radius / (12.0 * viscosity);
}

double RingSolution::surface_density(double r, double tau) const {
  if (!(tau > 0.0) || !(r >= 0.0)) return kNaN;
  // Eq. 11 in scaled form: Sigma = m/(pi r0^2 tau) S(x, tau).
  const double x = r / ring_radius;
  return disc_mass / (std::numbers::pi * ring_radius * ring_radius * tau) * ring_shape(x, tau);
}

double RingSolution::radial_velocity(double r, double tau) const {
  if (!(tau > 0.0) || !(r >= 0.0)) return kNaN;
  // Eq. 12: v_r = 6 nu/(r0 tau) [x - Ĩ_{-3/4}(z)/Ĩ_{1/4}(z)] (the e^{-z} scalings cancel).
  // As z -> 0 the ratio ~ (2/z) Gamma(5/4)/Gamma(1/4) = tau/(4x), i.e. v_r -> -3 nu/(2 r), the
  // steady inflow of a constant-nu disc, so the limit at r = 0 is -infinity.
  if (r == 0.0) return -kInf;
  const double x = r / ring_radius;
  const double z = 2.0 * x / tau;
  const double pre = 6.0 * viscosity / (ring_radius * tau);
  if (z < kScaledBesselSwitch) {
    // Ĩ_{-3/4}/Ĩ_{1/4} = (z/2)^{-1} A/B with A, B the reduced sums of reduced_series_sum;
    // (z/2)^{-1} = tau/x. Both sums in one loop (same q); the A terms decay more slowly
    // (k - 3/4 < k + 1/4), so convergence is tested on A.
    const double q = 0.25 * z * z;
    double ta = kInvGamma1_4;
    double tb = kInvGamma5_4;
    double sa = ta;
    double sb = tb;
    for (int k = 1; k < 1000; ++k) {
      const double denom_a = k * (k - 0.75);
      ta *= q / denom_a;
      tb *= q / (k * (k + 0.25));
      sa += ta;
      sb += tb;
      if (denom_a > 2.0 * q && ta <= kSeriesEps * sa) break;
    }
    return pre * (x - (tau / x) * (sa / sb));
  }
  return pre * (x - hankel_scaled(-0.75, z) / hankel_scaled(0.25, z));
}

double RingSolution::enclosed_mass(double r, double tau) const {
  if (!(tau > 0.0) || !(r >= 0.0)) return kNaN;
  // integral_0^r 2 pi r' Sigma dr' = (2 m / tau) integral_0^{r/r0} x S(x, tau) dx.
  return 2.0 * disc_mass / tau * integrate_mass(0.0, r / ring_radius, tau);
}

double RingSolution::accreted_mass(double tau) const {
  if (!(tau > 0.0)) return kNaN;
  // m Q(1/4, 1/tau): time integral of the inflow 3 pi nu Sigma(0, tau) through r = 0 (see header).
  return disc_mass * regularized_gamma_q(0.25, kInvGamma1_4, 1.0 / tau);
}

double RingSolution::annulus_mean_surface_density(double r_in, double r_out, double tau) const {
  if (!(tau > 0.0) || !(r_in >= 0.0) || !(r_out >= r_in)) return kNaN;
  if (r_out == r_in) return surface_density(r_in, tau);
  const double mass = 2.0 * disc_mass / tau *
                      integrate_mass(r_in / ring_radius, r_out / ring_radius, tau);
  return mass / (std::numbers::pi * (r_out * r_out - r_in * r_in));
}

}  // namespace sphdisk
