// Kernel normalisation (integral of W over the plane/space = 1) and w'(q)/q against finite differences.
#include <gtest/gtest.h>

#include <numbers>

#include "physics/kernels.hpp"

using namespace sphdisk;

template <class K>
double integral_2d(double h) {
  const KernelAt<K, 2> k(h);
  const int n = 200000;
  double s = 0, dr = 2 * h / n;
  for (int i = 0; i < n; ++i) {
    const double r = (i + 0.5) * dr;
    s += k.W(r) * 2 * std::numbers::pi * r * dr;
  }
  return s;
}
template <class K>
double integral_3d(double h) {
  const KernelAt<K, 3> k(h);
  const int n = 200000;
  double s = 0, dr = 2 * h / n;
  for (int i = 0; i < n; ++i) {
    const double r = (i + 0.5) * dr;
    s += k.W(r) * 4 * std::numbers::pi * r * r * dr;
  }
  return s;
}

template <class K>
void check_derivative() {
  for (double q = 0.05; q < 2.0; q += 0.0731) {
    const double eps = 1e-6;
    const double fd = (K::w(q + eps) - K::w(q - eps)) / (2 * eps);
    EXPECT_NEAR(K::dw_over_q(q) * q, fd, 1e-8) << K::name << " q=" << q;
  }
  EXPECT_EQ(K::w(2.0), 0.0);
  EXPECT_EQ(K::dw_over_q(2.5), 0.0);
}

TEST(Kernels, NormalisedIn2D) {
  EXPECT_NEAR(integral_2d<CubicSpline>(0.7), 1.0, 1e-8);
  EXPECT_NEAR(integral_2d<WendlandC2>(0.7), 1.0, 1e-8);
  EXPECT_NEAR(integral_2d<WendlandC4>(0.7), 1.0, 1e-8);
}

TEST(Kernels, NormalisedIn3D) {
  EXPECT_NEAR(integral_3d<CubicSpline>(1.3), 1.0, 1e-8);
  EXPECT_NEAR(integral_3d<WendlandC2>(1.3), 1.0, 1e-8);
  EXPECT_NEAR(integral_3d<WendlandC4>(1.3), 1.0, 1e-8);
}

TEST(Kernels, DerivativeMatchesFiniteDifference) {
  check_derivative<CubicSpline>();
  check_derivative<WendlandC2>();
  check_derivative<WendlandC4>();
}

TEST(Kernels, GradientScalesWithSmoothingLength) {
  const KernelAt<CubicSpline, 2> k(0.5);
  const double r = 0.3, eps = 1e-7;
  EXPECT_NEAR(k.dW_over_r(r) * r, (k.W(r + eps) - k.W(r - eps)) / (2 * eps), 1e-6);
}

TEST(Kernels, UnknownNameIsAUserError) {
  EXPECT_THROW(kernel_from_name("gaussian"), UserError);
  EXPECT_EQ(kernel_from_name("wendland_c4"), KernelType::WendlandC4);
}

// dW/dh (for the smoothing-length Newton iteration) against a central difference in h.
template <class K, int D>
void check_h_derivative() {
  const double h = 0.37, dh = 1e-6;
  for (double r = 0.0; r < 2.0 * h; r += 0.013) {
    using Kern = KernelAt<K, D>;
    const double fd = (Kern(h + dh).W(r) - Kern(h - dh).W(r)) / (2 * dh);
    const double scale = Kern(h).W(0.0) / h;
    EXPECT_NEAR(Kern(h).dW_dh(r), fd, 1e-6 * scale) << K::name << " r " << r;
  }
}

TEST(Kernels, SmoothingLengthDerivativeMatchesFiniteDifference) {
  check_h_derivative<CubicSpline, 2>();
  check_h_derivative<CubicSpline, 3>();
  check_h_derivative<WendlandC2, 2>();
  check_h_derivative<WendlandC4, 3>();
}

// w'(q) written without division equals q (w'(q)/q).
TEST(Kernels, DerivativeFormsAgree) {
  for (double q = 0.0; q < 2.2; q += 0.01) {
    EXPECT_NEAR(CubicSpline::dw(q), q * CubicSpline::dw_over_q(q), 1e-14);
    EXPECT_NEAR(WendlandC2::dw(q), q * WendlandC2::dw_over_q(q), 1e-14);
    EXPECT_NEAR(WendlandC4::dw(q), q * WendlandC4::dw_over_q(q), 1e-14);
  }
}
