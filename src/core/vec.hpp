#pragma once
// Small fixed-size vectors and matrices for D = 2 or 3 dimensions. The dimension is a template
// parameter everywhere in the physics so that 3D is an instantiation, not a rewrite.
#include <array>
#include <cmath>
#include <cstddef>
#include <type_traits>

namespace sphdisk {

template <int D>
struct Vec {
  std::array<double, D> c{};
  constexpr double& operator[](int k) { return c[static_cast<std::size_t>(k)]; }
  constexpr double operator[](int k) const { return c[static_cast<std::size_t>(k)]; }
  constexpr Vec& operator+=(const Vec& o) {
    for (int k = 0; k < D; ++k) (*this)[k] += o[k];
    return *this;
  }
  constexpr Vec& operator-=(const Vec& o) {
    for (int k = 0; k < D; ++k) (*this)[k] -= o[k];
    return *this;
  }
  constexpr Vec& operator*=(double s) {
    for (int k = 0; k < D; ++k) (*this)[k] *= s;
    return *this;
  }
  friend constexpr Vec operator+(Vec a, const Vec& b) { return a += b; }
  friend constexpr Vec operator-(Vec a, const Vec& b) { return a -= b; }
  friend constexpr Vec operator*(Vec a, double s) { return a *= s; }
  friend constexpr Vec operator*(double s, Vec a) { return a *= s; }
  friend constexpr Vec operator-(Vec a) {  // the sign flipped exactly
    for (int k = 0; k < D; ++k) a[k] = -a[k];
    return a;
  }
  friend constexpr bool operator==(const Vec&, const Vec&) = default;
};

// Sums start from the first product, not from 0: 0 + x cannot be dropped by the compiler (it
// turns -0 into +0), so a zero start costs an instruction or two in every pair loop.
template <int D>
constexpr double dot(const Vec<D>& a, const Vec<D>& b) {
  double s = a[0] * b[0];
  for (int k = 1; k < D; ++k) s += a[k] * b[k];
  return s;
}
// Where the build has FMA (native builds), the squares are fused explicitly, so that every squared
// distance in the program, the vectorised ones of neighbours/candidate_scan.cpp included, is formed
// by the same operations whatever the compiler chooses to contract.
template <int D>
constexpr double norm2(const Vec<D>& a) {
#ifdef __FMA__
  if (!std::is_constant_evaluated()) {
    double s = a[0] * a[0];
    for (int k = 1; k < D; ++k) s = std::fma(a[k], a[k], s);
    return s;
  }
#endif
  return dot(a, a);
}
template <int D>
inline double norm(const Vec<D>& a) { return std::sqrt(norm2(a)); }

// Row-major D x D matrix; m(a, b) is the component alpha = a, beta = b of a tensor. All arithmetic
// is on Mat<D> (double); Mat<D, float> is only a storage form (core/particles.hpp, kReduced fields),
// converted with as_double / store.
template <int D, class T = double>
struct Mat {
  std::array<T, D * D> c{};
  constexpr T& operator()(int a, int b) { return c[static_cast<std::size_t>(a * D + b)]; }
  constexpr T operator()(int a, int b) const { return c[static_cast<std::size_t>(a * D + b)]; }
  constexpr double trace() const {
    double t = 0;
    for (int k = 0; k < D; ++k) t += (*this)(k, k);
    return t;
  }
  friend constexpr bool operator==(const Mat&, const Mat&) = default;
};

template <class T>
inline constexpr bool is_mat_v = false;
template <int D, class T>
inline constexpr bool is_mat_v<Mat<D, T>> = true;

// A stored matrix in double precision (exact: every float is a double).
template <int D, class T>
constexpr Mat<D> as_double(const Mat<D, T>& m) {
  if constexpr (std::is_same_v<T, double>) {
    return m;
  } else {
    Mat<D> r;
    for (std::size_t k = 0; k < r.c.size(); ++k) r.c[k] = static_cast<double>(m.c[k]);
    return r;
  }
}

// Stores a double-precision result in a field's storage form (rounded to nearest when it holds
// floats).
template <int D, class T>
constexpr void store(Mat<D, T>& to, const Mat<D>& m) {
  for (std::size_t k = 0; k < to.c.size(); ++k) to.c[k] = static_cast<T>(m.c[k]);
}
// Stores m in a field's storage form and returns what was stored, in double precision: what every
// later reader of the field gets, for sums that must pair with theirs term by term (energy). Not
// inlined: inlined where m came from one of two branches (the moment correction's inverse or the
// identity), g++ 12 -O3 used m itself, not its rounding to float (the preset "single"'s
// conservation tests failed by ~1e-8 of the work).
template <int D, class T>
[[gnu::noinline]] Mat<D> store_and_read(Mat<D, T>& to, const Mat<D>& m) {
  Mat<D, T> stored;
  store(stored, m);
  to = stored;
  return as_double(stored);
}
template <class T>
  requires std::is_floating_point_v<T>
constexpr void store(T& to, double x) {
  to = static_cast<T>(x);
}

// t . v with t_ab v_b (Einstein summation over b).
template <int D>
constexpr Vec<D> contract(const Mat<D>& t, const Vec<D>& v) {
  Vec<D> r;
  for (int a = 0; a < D; ++a) {
    r[a] = t(a, 0) * v[0];  // from the first product (see dot)
    for (int b = 1; b < D; ++b) r[a] += t(a, b) * v[b];
  }
  return r;
}

// Matrix product (a b)_ik = a_ij b_jk.
template <int D>
constexpr Mat<D> operator*(const Mat<D>& a, const Mat<D>& b) {
  Mat<D> r;
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j)
      for (int k = 0; k < D; ++k) r(i, k) += a(i, j) * b(j, k);
  return r;
}

template <int D>
constexpr Mat<D> identity() {
  Mat<D> r;
  for (int a = 0; a < D; ++a) r(a, a) = 1.0;
  return r;
}

// Double contraction s_ab v_ab.
template <int D>
constexpr double double_dot(const Mat<D>& s, const Mat<D>& v) {
  double r = 0;
  for (std::size_t k = 0; k < s.c.size(); ++k) r += s.c[k] * v.c[k];
  return r;
}

// inv = m^-1 for D = 2 or 3, unless m is singular or badly conditioned (|det| below 1e-6 of the
// scale (trace/D)^D, e.g. a particle with fewer than D neighbours in general position).
template <int D>
bool invert_if_well_conditioned(const Mat<D>& m, Mat<D>& inv) {
  static_assert(D == 2 || D == 3);
  const double scale = m.trace() / D;
  if (!(scale > 0)) return false;
  if constexpr (D == 2) {
    const double det = m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0);
    if (!(std::abs(det) > 1e-6 * scale * scale)) return false;
    inv(0, 0) = m(1, 1) / det, inv(0, 1) = -m(0, 1) / det;
    inv(1, 0) = -m(1, 0) / det, inv(1, 1) = m(0, 0) / det;
  } else {
    Mat<3> c;  // cofactors
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        c(b, a) = m((a + 1) % 3, (b + 1) % 3) * m((a + 2) % 3, (b + 2) % 3) - m((a + 1) % 3, (b + 2) % 3) * m((a + 2) % 3, (b + 1) % 3);
    const double det = m(0, 0) * c(0, 0) + m(0, 1) * c(1, 0) + m(0, 2) * c(2, 0);
    if (!(std::abs(det) > 1e-6 * scale * scale * scale)) return false;
    for (std::size_t k = 0; k < 9; ++k) inv.c[k] = c.c[k] / det;
  }
  return true;
}

}  // namespace sphdisk
