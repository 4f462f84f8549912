#include "problems/sedov_solution.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace sphdisk {

namespace {

// The similarity ODEs for y = (D, U, P) in xi, from the continuity, momentum and entropy equations
// with rho = rho0 D, v = R' U, p = rho0 R'^2 P and R ~ t^delta, delta = 2 / (j + 2):
//   (U - xi) D' + D (U' + (j - 1) U / xi) = 0
//   (U - xi) U' + P' / D = k U,                 k = (1 - delta) / delta
//   (U - xi) (P' / P - gamma D' / D) = 2 k
// solved for the derivatives (w = U - xi, c^2 = gamma P / D).
std::array<double, 3> derivatives(double xi, const std::array<double, 3>& y, double gamma, int j) {
  const double delta = 2.0 / (j + 2.0), k = (1.0 - delta) / delta;
  const double D = y[0], U = y[1], P = y[2];
  const double w = U - xi, c2 = gamma * P / D;
  const double geometric = (j - 1.0) * U / xi;
  // From the entropy equation P'/D = (P/D)(2k/w + gamma D'/D) and continuity D'/D = -(U' + geometric)/w:
  // w U' + (P/D)(2k - gamma (U' + geometric)) / w = k U.
  const double dU = (k * U * w - (P / D) * (2.0 * k - gamma * geometric)) / (w * w - c2);
  const double dlnD = -(dU + geometric) / w;
  const double dP = P * (2.0 * k / w + gamma * dlnD);
  return {D * dlnD, dU, dP};
}

}  // namespace

SedovSolution::SedovSolution(double gamma, int dimension) : gamma_(gamma), j_(dimension) {
  if (!(gamma > 1.0) || (dimension != 2 && dimension != 3)) throw std::invalid_argument("SedovSolution: gamma > 1, dimension 2 or 3");
  // Strong-shock jump conditions at xi = 1 (shock speed R').
  std::array<double, 3> y{(gamma + 1.0) / (gamma - 1.0), 2.0 / (gamma + 1.0), 2.0 / (gamma + 1.0)};
  // Classical fourth-order Runge-Kutta inward on a uniform grid in ln xi (the profile steepens
  // towards the centre), to xi = 1e-4.
  const int steps = 20000;
  const double ln_end = std::log(1e-4), h = ln_end / steps;
  auto f = [&](double s, const std::array<double, 3>& v) {
    const double xi = std::exp(s);
    auto d = derivatives(xi, v, gamma, j_);
    for (auto& x : d) x *= xi;  // d/d ln xi
    return d;
  };
  auto axpy = [](const std::array<double, 3>& a, double c, const std::array<double, 3>& b) {
    return std::array<double, 3>{a[0] + c * b[0], a[1] + c * b[1], a[2] + c * b[2]};
  };
  double s = 0.0;
  for (int n = 0; n <= steps; ++n) {
    xi_.push_back(std::exp(s));
    d_.push_back(y[0]);
    u_.push_back(y[1]);
    p_.push_back(y[2]);
    if (n == steps) break;
    const auto k1 = f(s, y), k2 = f(s + 0.5 * h, axpy(y, 0.5 * h, k1)), k3 = f(s + 0.5 * h, axpy(y, 0.5 * h, k2)),
               k4 = f(s + h, axpy(y, h, k3));
    for (int c = 0; c < 3; ++c) y[c] += h / 6.0 * (k1[c] + 2.0 * k2[c] + 2.0 * k3[c] + k4[c]);
    s += h;
  }
  // Energy: E = rho0 R'^2 R^j A_j I with I = int xi^(j-1) (D U^2 / 2 + P / (gamma - 1)) dxi
  // (trapezoids in ln xi; the core below the grid holds a negligible share), A_3 = 4 pi, A_2 = 2 pi;
  // with R' = delta R / t and R^(j+2) = xi0^(j+2) E t^2 / rho0: xi0 = (delta^2 A_j I)^(-1/(j+2)).
  auto integrand = [&](std::size_t n) {
    return std::pow(xi_[n], j_) * (0.5 * d_[n] * u_[n] * u_[n] + p_[n] / (gamma - 1.0));  // xi^(j-1) dxi = xi^j dln xi
  };
  double I = 0.0;
  for (std::size_t n = 0; n + 1 < xi_.size(); ++n) I += 0.5 * (integrand(n) + integrand(n + 1)) * -h;
  const double delta = 2.0 / (j_ + 2.0), area = j_ == 3 ? 4.0 * std::numbers::pi : 2.0 * std::numbers::pi;
  xi0_ = std::pow(delta * delta * area * I, -1.0 / (j_ + 2.0));
}

double SedovSolution::shock_radius(double energy, double rho0, double t) const {
  return xi0_ * std::pow(energy * t * t / rho0, 1.0 / (j_ + 2.0));
}

SedovSolution::State SedovSolution::at(double r, double energy, double rho0, double t) const {
  const double R = shock_radius(energy, rho0, t);
  if (r >= R) return {rho0, 0.0, 0.0};
  const double xi = r / R, speed = 2.0 / (j_ + 2.0) * R / t;
  if (xi <= xi_.back()) return {rho0 * d_.back(), speed * u_.back(), rho0 * speed * speed * p_.back()};
  // xi_ descends: the first grid point below xi, then linear interpolation.
  const auto it = std::lower_bound(xi_.begin(), xi_.end(), xi, [](double a, double b) { return a > b; });
  const std::size_t n = static_cast<std::size_t>(it - xi_.begin());
  const std::size_t a = n == 0 ? 0 : n - 1, b = n == 0 ? 1 : n;
  const double w = (xi - xi_[a]) / (xi_[b] - xi_[a]);
  auto lerp = [&](const std::vector<double>& v) { return v[a] + w * (v[b] - v[a]); };
  return {rho0 * lerp(d_), speed * lerp(u_), rho0 * speed * speed * lerp(p_)};
}

}  // namespace sphdisk
