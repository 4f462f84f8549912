#pragma once
// SPH smoothing kernels W(r, h) = sigma_D h^-D w(q), q = r/h, compact support 2h
// (docs/physics.md sec. 2). Each kernel gives w(q) and w'(q)/q; the latter is what the gradient needs,
// since grad_i W_ij = (x_i - x_j) / r * dW/dr = (x_i - x_j) sigma_D h^-(D+2) w'(q)/q, and it stays
// finite at q = 0.
#include <numbers>
#include <string_view>

#include "core/error.hpp"
#include "core/named_choice.hpp"

namespace sphdisk {

struct CubicSpline {  // M4 B-spline (Monaghan & Lattanzio 1985)
  static constexpr std::string_view name = "cubic";
  // Written as 0.25 [(2-q)_+^3 - 4 (1-q)_+^3] with (x)_+ = max(x, 0): no branches, so the compiler
  // emits selects instead of mispredicted jumps in the pair loops.
  static constexpr double w(double q) {
    const double a = q < 2.0 ? 2.0 - q : 0.0, b = q < 1.0 ? 1.0 - q : 0.0;
    return 0.25 * (a * a * a - 4.0 * b * b * b);
  }
  // w'(q)/q: 0.75 (3q - 4) for q < 1 and -0.75 (2-q)^2 / q for 1 <= q < 2 (finite at q = 0).
  static constexpr double dw_over_q(double q) {
    const double a = q < 2.0 ? 2.0 - q : 0.0;
    const double outer = -0.75 * a * a / (q < 1.0 ? 1.0 : q);
    return q < 1.0 ? 0.75 * (3.0 * q - 4.0) : outer;
  }
  // w'(q) = 3 (1-q)_+^2 - 0.75 (2-q)_+^2: no division, for loops that need dW/dr itself.
  static constexpr double dw(double q) {
    const double a = q < 2.0 ? 2.0 - q : 0.0, b = q < 1.0 ? 1.0 - q : 0.0;
    return 3.0 * b * b - 0.75 * a * a;
  }
  template <int D>
  static constexpr double sigma() {
    if constexpr (D == 1) return 2.0 / 3.0;
    if constexpr (D == 2) return 10.0 / (7.0 * std::numbers::pi);
    return 1.0 / std::numbers::pi;
  }
};

struct WendlandC2 {  // Wendland (1995); no pairing instability (Dehnen & Aly 2012)
  static constexpr std::string_view name = "wendland_c2";
  static constexpr double w(double q) {
    if (q >= 2.0) return 0.0;
    const double t = 1.0 - 0.5 * q, t2 = t * t;
    return t2 * t2 * (2.0 * q + 1.0);
  }
  static constexpr double dw_over_q(double q) {  // (5/8)(q-2)^3
    if (q >= 2.0) return 0.0;
    const double t = q - 2.0;
    return 0.625 * t * t * t;
  }
  static constexpr double dw(double q) { return q * dw_over_q(q); }
  template <int D>
  static constexpr double sigma() {
    static_assert(D >= 2, "Wendland C2 is defined here for 2D and 3D");
    if constexpr (D == 2) return 7.0 / (4.0 * std::numbers::pi);
    return 21.0 / (16.0 * std::numbers::pi);
  }
};

struct WendlandC4 {
  static constexpr std::string_view name = "wendland_c4";
  static constexpr double w(double q) {
    if (q >= 2.0) return 0.0;
    const double t = 1.0 - 0.5 * q, t2 = t * t;
    return t2 * t2 * t2 * (35.0 / 12.0 * q * q + 3.0 * q + 1.0);
  }
  static constexpr double dw_over_q(double q) {  // (7/96)(q-2)^5(5q+2)
    if (q >= 2.0) return 0.0;
    const double t = q - 2.0, t2 = t * t;
    return 7.0 / 96.0 * t2 * t2 * t * (5.0 * q + 2.0);
  }
  static constexpr double dw(double q) { return q * dw_over_q(q); }
  template <int D>
  static constexpr double sigma() {
    static_assert(D >= 2, "Wendland C4 is defined here for 2D and 3D");
    if constexpr (D == 2) return 9.0 / (4.0 * std::numbers::pi);
    return 495.0 / (256.0 * std::numbers::pi);
  }
};

// A kernel bound to one smoothing length (the global one of P98 sec. 5.3, or one particle's).
template <class K, int D>
struct KernelAt {
  double h;
  double inv_h;
  double w_norm;     // sigma_D / h^D
  double grad_norm;  // sigma_D / h^(D+2)
  double support2;   // (2h)^2

  explicit KernelAt(double h_) : h(h_), inv_h(1.0 / h_) {
    double hd = 1.0;
    for (int k = 0; k < D; ++k) hd *= h;
    w_norm = K::template sigma<D>() / hd;
    grad_norm = w_norm / (h * h);
    support2 = 4.0 * h * h;
  }
  double W(double r) const { return w_norm * K::w(r * inv_h); }
  // dW/dr / r: multiply by (x_i - x_j) to get grad_i W_ij.
  double dW_over_r(double r) const { return grad_norm * K::dw_over_q(r * inv_h); }
  double dW_dr(double r) const { return w_norm * inv_h * K::dw(r * inv_h); }
  // dW/dh = -(sigma_D / h^(D+1)) (D w(q) + q w'(q)), for the smoothing-length iteration.
  double dW_dh(double r) const {
    const double q = r * inv_h;
    return -w_norm * inv_h * (D * K::w(q) + q * K::dw(q));
  }
};

enum class KernelType { Cubic, WendlandC2, WendlandC4 };

inline KernelType kernel_from_name(std::string_view s) {
  static constexpr NamedChoice<KernelType> kNames[] = {{CubicSpline::name, KernelType::Cubic},
                                                       {WendlandC2::name, KernelType::WendlandC2},
                                                       {WendlandC4::name, KernelType::WendlandC4}};
  return choice_from_name<KernelType>("sph.kernel", s, kNames);
}

// Calls f(K{}) with the kernel type selected at run time, so inner loops are compiled per kernel.
template <class F>
decltype(auto) with_kernel(KernelType t, F&& f) {
  switch (t) {
    case KernelType::WendlandC2: return f(WendlandC2{});
    case KernelType::WendlandC4: return f(WendlandC4{});
    case KernelType::Cubic: break;
  }
  return f(CubicSpline{});
}

}  // namespace sphdisk
