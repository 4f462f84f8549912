// The pair functions of physics/pair_terms.hpp against values worked out by hand for hand-placed
// particles, and the list bodies that call them (list_sums.hpp, density.hpp, viscous_stress.hpp)
// against the sums of those functions over the particles' pairs. All inputs are small dyadic
// numbers, so every product and sum is exact and the comparisons are too.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/particles.hpp"
#include "core/vec.hpp"
#include "neighbours/pair_lists.hpp"
#include "physics/density.hpp"
#include "physics/kernels.hpp"
#include "physics/list_sums.hpp"
#include "physics/pair_factors.hpp"
#include "physics/pair_terms.hpp"
#include "physics/viscous_stress.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

namespace {

Vec<2> vec(double x, double y) { return Vec<2>{{x, y}}; }
Mat<2> mat(double xx, double xy, double yx, double yy) { return Mat<2>{{xx, xy, yx, yy}}; }

void expect_vec(const Vec<2>& got, const Vec<2>& want, const std::string& what) {
  for (int a = 0; a < 2; ++a) EXPECT_EQ(got[a], want[a]) << what << ", component " << a;
}

void expect_mat(const Mat<2>& got, const Mat<2>& want, const std::string& what) {
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) EXPECT_EQ(got(a, b), want(a, b)) << what << ", component (" << a << ", " << b << ")";
}

// Four particles in 2D. ln rho is chosen, not ln of rho: the pair terms take it as given. Pr = P/rho^2.
//      x         v           m    rho   V = m/rho  S                     C                      ln rho  Pr
//  0   (0, 0)    (1, 2)      2    4     0.5        [[1, 2], [3, -1]]     [[2, 0], [0, 1]]       0       0.5
//  1   (2, 1)    (0, 1)      1    0.5   2          [[0, 1], [-1, 2]]     [[1, .5], [.5, 1]]     0.5     0.125
//  2   (0, 2)    (-1, 0)     4    8     0.5        [[2, 0], [1, -2]]     I                      1       1
//  3   (-1, -1)  (.5, .5)    0.5  1     0.5        [[-1, .5], [0, 0]]    [[.5, 0], [0, 2]]      -0.5    2
// Particle 0 owns the half list {1, 2, 3} with kernel-gradient factors F = {-1, -0.5, -2};
// 0, 1 and 2 are writable, 3 is not (a ghost).
struct Particle {
  Vec<2> x, v;
  double m, rho;
  Mat<2> S, C;
  double log_rho, Pr;
};

const std::array<Particle, 4> kParticles = {{
    {vec(0, 0), vec(1, 2), 2.0, 4.0, mat(1, 2, 3, -1), mat(2, 0, 0, 1), 0.0, 0.5},
    {vec(2, 1), vec(0, 1), 1.0, 0.5, mat(0, 1, -1, 2), mat(1, 0.5, 0.5, 1), 0.5, 0.125},
    {vec(0, 2), vec(-1, 0), 4.0, 8.0, mat(2, 0, 1, -2), mat(1, 0, 0, 1), 1.0, 1.0},
    {vec(-1, -1), vec(0.5, 0.5), 0.5, 1.0, mat(-1, 0.5, 0, 0), mat(0.5, 0, 0, 2), -0.5, 2.0},
}};
constexpr std::uint32_t kOwner = 0;
const std::vector<std::uint32_t> kPartners = {1, 2, 3};
const std::vector<float> kFactors = {-1.0f, -0.5f, -2.0f};
constexpr std::size_t kWritable = 3;

double volume(const Particle& p) { return p.m / p.rho; }

// The pair (0, 1) worked by hand below: dx = x_0 - x_1 = (-2, -1), F = -1,
// g = grad_0 W_01 = dx F = (2, 1), dv = v_1 - v_0 = (-1, -1), v_0 - v_1 = (1, 1).
const Particle& P0 = kParticles[0];
const Particle& P1 = kParticles[1];
const Vec<2> kDx = vec(-2, -1), kDv = vec(-1, -1), kG = vec(2, 1);
constexpr double kF = -1.0;

}  // namespace

// Cubic spline in 2D, h = 1: sigma_2 = 10 / (7 pi), F = (dW/dr) / r = sigma w'(q) / r with
// w'(q) = 3 (1-q)^2 - 0.75 (2-q)^2 for q < 1 and -0.75 (2-q)^2 for 1 <= q < 2.
TEST(PairTerms, CubicSplineGradientFactorByHand) {
  const double sigma = 10.0 / (7.0 * std::numbers::pi);
  const KernelAt<CubicSpline, 2> h1(1.0), h2(2.0);
  // q = 0.5: w' = 3 (0.25) - 0.75 (2.25) = -0.9375, F = -0.9375 sigma / 0.5 = -1.875 sigma.
  EXPECT_DOUBLE_EQ(h1.dW_over_r(0.5), -1.875 * sigma);
  // q = 1.5: w' = -0.75 (0.25) = -0.1875, F = -0.1875 sigma / 1.5 = -0.125 sigma.
  EXPECT_DOUBLE_EQ(h1.dW_over_r(1.5), -0.125 * sigma);
  // The pair average at r = 1 of h_i = 1 (q = 1: dW/dr = sigma (-0.75)) and h_j = 2
  // (q = 0.5: dW/dr = sigma / 2^3 (-0.9375) = -0.1171875 sigma): (-0.75 - 0.1171875) sigma / (2 r).
  EXPECT_DOUBLE_EQ(pair_average_factor<CubicSpline>(slope_of(h1), slope_of(h2), 1.0), -0.43359375 * sigma);
  // grad_i W_ij = (x_i - x_j) F: (-2, -1) (-1) = (2, 1).
  expect_vec(kernel_gradient(kDx, kF), kG, "grad_0 W_01");
}

// m_j W_ij: with W = 0.375, particle 1's term in rho_0 is 1 (0.375), particle 0's in rho_1 is 2 (0.375).
TEST(PairTerms, DensityTermByHand) {
  EXPECT_EQ(density_term(P1.m, 0.375), 0.375);
  EXPECT_EQ(density_term(P0.m, 0.375), 0.75);
}

// Eq. 8 and the moment matrix for the pair (0, 1):
//   dv (x) dx = (-1, -1) (x) (-2, -1) = [[2, 1], [2, 1]],  dx (x) dx = [[4, 2], [2, 1]].
//   For 0, weight F V_1 = -1 (2) = -2:   V += -2 [[2, 1], [2, 1]] = [[-4, -2], [-4, -2]],
//                                        M += 2 [[4, 2], [2, 1]] = [[8, 4], [4, 2]].
//   For 1, weight F V_0 = -1 (0.5) = -0.5: V += [[-1, -0.5], [-1, -0.5]],  M += [[2, 1], [1, 0.5]].
// (From the definitions: V_0 = V_1 (v_1 - v_0) (x) g = 2 (-1, -1) (x) (2, 1); M_0 = -V_1 dx (x) g.)
TEST(PairTerms, GradientTermsByHand) {
  const GradientSums<2> products = gradient_pair_products(kDv, kDx);
  expect_mat(products.V, mat(2, 1, 2, 1), "dv (x) dx");
  expect_mat(products.M, mat(4, 2, 2, 1), "dx (x) dx");
  const GradientSums<2> to_0 = gradient_term(kF, volume(P1), products);
  expect_mat(to_0.V, mat(-4, -2, -4, -2), "V term of 0");
  expect_mat(to_0.M, mat(8, 4, 4, 2), "M term of 0");
  const GradientSums<2> to_1 = gradient_term(kF, volume(P0), products);
  expect_mat(to_1.V, mat(-1, -0.5, -1, -0.5), "V term of 1");
  expect_mat(to_1.M, mat(2, 1, 1, 0.5), "M term of 1");
}

// Eq. 6, conservative form, for the pair (0, 1):
//   X = S_0 / rho_1 + S_1 / rho_0 = 2 [[1, 2], [3, -1]] + 0.25 [[0, 1], [-1, 2]] = [[2, 4.25], [5.75, -1.5]],
//   f = X . g = (2 (2) + 4.25 (1), 5.75 (2) - 1.5 (1)) = (8.25, 10);
//   a_0 += m_1 f = (8.25, 10), a_1 -= m_0 f = (-16.5, -20).
TEST(PairTerms, ConservativeForceByHand) {
  const Vec<2> f = conservative_viscous_pair(P0.S, P1.S, 1.0 / P0.rho, 1.0 / P1.rho, kG);
  expect_vec(f, vec(8.25, 10), "f");
  expect_vec(f * P1.m, vec(8.25, 10), "a_0");
  expect_vec(f * -P0.m, vec(-16.5, -20), "a_1");
}

// Pressure for the pair (0, 1): (Pr_0 + Pr_1) g = 0.625 (2, 1) = (1.25, 0.625), subtracted from f.
// Work: (v_0 - v_1) . g = (1, 1) . (2, 1) = 3; du_0 += Pr_0 m_1 3 = 1.5, du_1 += Pr_1 m_0 3 = 0.75.
TEST(PairTerms, PressureForceAndWorkByHand) {
  expect_vec(pressure_pair(P0.Pr, P1.Pr, kG), vec(1.25, 0.625), "pressure");
  const PairTerms<double> work = pressure_work_pair(P0.Pr, P1.Pr, P0.m, P1.m, P0.v - P1.v, kG);
  EXPECT_EQ(work.to_i, 1.5);
  EXPECT_EQ(work.to_j, 0.75);
}

// Consistent form for the pair (0, 1), dl = ln rho_1 - ln rho_0 = 0.5:
//   dS = S_1 - S_0 = [[-1, -1], [-4, 3]],
//   X_0 = dS + 0.5 S_0 = [[-0.5, 0], [-2.5, 2.5]],  X_1 = dS + 0.5 S_1 = [[-1, -0.5], [-4.5, 4]],
//   C_0 g = [[2, 0], [0, 1]] (2, 1) = (4, 1),       C_1 g = [[1, .5], [.5, 1]] (2, 1) = (2.5, 2),
//   a_0 += V_1 X_0 . C_0 g = 2 (-2, -7.5) = (-4, -15),
//   a_1 += V_0 X_1 . C_1 g = 0.5 (-3.5, -3.25) = (-1.75, -1.625)
// (a_1 from the definition: V_0 [S_0 - S_1 + S_1 (ln rho_0 - ln rho_1)] . C_1 (-g), the same).
TEST(PairTerms, ConsistentForceByHand) {
  const PairTerms<Vec<2>> G = linear_corrected_gradients(P0.C, P1.C, kG);
  expect_vec(G.to_i, vec(4, 1), "C_0 g");
  expect_vec(G.to_j, vec(2.5, 2), "C_1 g");
  const PairTerms<Vec<2>> a = consistent_viscous_pair(P0.S, P1.S, G, P1.log_rho - P0.log_rho, volume(P0), volume(P1));
  expect_vec(a.to_i, vec(-4, -15), "a_0");
  expect_vec(a.to_j, vec(-1.75, -1.625), "a_1");
}

// The mixed correction's sums for particle 0 from its three pairs with W = 0.125, 0.5, 1
// ((0, 2): dx = (0, -2), F = -0.5, g = (0, 1), dv = (-2, -2), V_2 = 0.5; (0, 3): dx = (1, 1), F = -2,
// g = (-2, -2), dv = (-0.5, -1.5), V_3 = 0.5):
//   (0, 1): V W = 0.25, V g = (4, 2),   V W dv = (-0.25, -0.25), V W dx = (-0.5, -0.25);
//   (0, 2): V W = 0.25, V g = (0, 0.5), V W dv = (-0.5, -0.5),   V W dx = (0, -0.5);
//   (0, 3): V W = 0.5,  V g = (-1, -1), V W dv = (-0.25, -0.75), V W dx = (0.5, 0.5);
//   sums w = 1, g = (3, 1.5), w_dv = (-1, -1.5), w_dx = (0, -0.25), so e = (3, 1.5).
// With eq. 8's V = [[-3.5, -2.5], [-2.5, -1.5]] and M = [[9, 5], [5, 4]] (det 11) of the three pairs:
//   V~ = V - w_dv (x) e = [[-0.5, -1], [2, 0.75]],  M~ = M + w_dx (x) e = [[9, 5], [4.25, 3.625]] (det 11.375).
// From the definitions: the shifted gradients V_k (g_k - W_k e) are (3.25, 1.625), (-0.75, 0.125) and
// (-2.5, -1.75), whose sum is zero (the zeroth moment); sum_k of dv_k (x) them is V~, of -dx_k (x)
// them is M~ (det M~ / det M = 1.034).
// Particle 1's terms of (0, 1) with W = 0.25 (V_0 W = 0.125): g -> -V_0 g = (-1, -0.5),
// w_dv = (0.125, 0.125), w_dx = (0.25, 0.125).
TEST(PairTerms, MixedCorrectionSumsByHand) {
  const ShepardSums<2> t10 = shepard_term(0.25, volume(P0), -kG, -kDv, -kDx);
  EXPECT_EQ(t10.w, 0.125);
  expect_vec(t10.g, vec(-1, -0.5), "-V_0 g");
  expect_vec(t10.w_dv, vec(0.125, 0.125), "V_0 W (v_0 - v_1)");
  expect_vec(t10.w_dx, vec(0.25, 0.125), "V_0 W (x_1 - x_0)");
  const Vec<2> dx[3] = {kDx, vec(0, -2), vec(1, 1)}, dv[3] = {kDv, vec(-2, -2), vec(-0.5, -1.5)};
  const double F[3] = {kF, -0.5, -2}, W[3] = {0.125, 0.5, 1}, V[3] = {volume(P1), 0.5, 0.5};
  GradientSums<2> two, three;
  for (int k = 0; k < 3; ++k) {
    GradientSums<2> t = gradient_term(F[k], V[k], gradient_pair_products(dv[k], dx[k]));
    t.shepard = shepard_term(W[k], V[k], kernel_gradient(dx[k], F[k]), dv[k], dx[k]);
    accumulate(three, t);
    if (k < 2) accumulate(two, t);
  }
  expect_vec(shepard_term(W[0], V[0], kG, kDv, kDx).g, vec(4, 2), "V_1 g");
  expect_mat(three.V, mat(-3.5, -2.5, -2.5, -1.5), "V");
  expect_mat(three.M, mat(9, 5, 5, 4), "M");
  EXPECT_EQ(three.shepard.w, 1.0);
  expect_vec(three.shepard.g, vec(3, 1.5), "sum V g");
  expect_vec(three.shepard.w_dv, vec(-1, -1.5), "sum V W dv");
  expect_vec(three.shepard.w_dx, vec(0, -0.25), "sum V W dx");
  // d = det M~ / det M - 1 = 0.375 / 11 > -1/4: the full shift.
  Vec<2> e;
  const GradientSums<2> mixed = mixed_gradient_sums(three, e);
  expect_vec(e, vec(3, 1.5), "e");
  expect_mat(mixed.V, mat(-0.5, -1, 2, 0.75), "V~");
  expect_mat(mixed.M, mat(9, 5, 4.25, 3.625), "M~");
  // The first two pairs alone: w = 0.5, e = (8, 5), M = [[8, 4], [4, 3]] (det 8), w_dx = (-0.5, -0.75),
  // M^-1 w_dx = (0.1875, -0.5), d = -1: the full shift would make M~ singular. It is scaled by
  // s(1) / 1 = 1/4 + 1/4 tanh(3), and det M~ / det M = 1 - s(1) = 0.5012 (just above one half).
  const GradientSums<2> scaled = mixed_gradient_sums(two, e);
  const double s1 = 0.25 + 0.25 * std::tanh(3.0);
  for (int a = 0; a < 2; ++a) EXPECT_NEAR(e[a], s1 * vec(8, 5)[a], 1e-15) << "e, scaled, component " << a;
  const Mat<2>& M = scaled.M;
  EXPECT_NEAR((M(0, 0) * M(1, 1) - M(0, 1) * M(1, 0)) / 8.0, 1.0 - s1, 1e-14);
  EXPECT_GT(1.0 - s1, 0.5);
  // A particle with no neighbour: no shift.
  mixed_gradient_sums(GradientSums<2>{}, e);
  expect_vec(e, vec(0, 0), "e without neighbours");
}

// The mixed correction's gradients for the pair (0, 1) with W = 0.25, s_0 = (1, 0.5), s_1 = (0.5, -1):
//   C_0 g - W s_0 = (4, 1) - (0.25, 0.125) = (3.75, 0.875),  C_1 g + W s_1 = (2.5, 2) + (0.125, -0.25) = (2.625, 1.75).
TEST(PairTerms, MixedCorrectedGradientsByHand) {
  const PairTerms<Vec<2>> G = mixed_corrected_gradients(P0.C, P1.C, vec(1, 0.5), vec(0.5, -1), 0.25, kG);
  expect_vec(G.to_i, vec(3.75, 0.875), "G_0");
  expect_vec(G.to_j, vec(2.625, 1.75), "G_1");
}

// Force correction for the pair (0, 1): G_01 = (C_0 g + C_1 g) / 2 = ((4, 1) + (2.5, 2)) / 2 = (3.25, 1.5).
// Its heating terms: for 0, dv (x) C_1 (dx F V_1) = (-1, -1) (x) C_1 (4, 2) = (-1, -1) (x) (5, 4);
// for 1, dv (x) C_0 (dx F V_0) = (-1, -1) (x) C_0 (1, 0.5) = (-1, -1) (x) (2, 0.5).
TEST(PairTerms, CorrectedGradientAndHeatingByHand) {
  expect_vec(corrected_pair_gradient(P0.C, P1.C, kG), vec(3.25, 1.5), "G_01");
  expect_mat(corrected_heating_term(P1.C, kF, volume(P1), kDv, kDx), mat(-5, -4, -5, -4), "heating term of 0");
  expect_mat(corrected_heating_term(P0.C, kF, volume(P0), kDv, kDx), mat(-2, -0.5, -2, -0.5), "heating term of 1");
}

namespace {

// The particles' fields as the list bodies read them.
struct Fields {
  std::vector<Vec<2>> pos, vel;
  std::vector<double> mass, inv_rho, volume, log_rho, Pr;
  std::vector<Mat<2, ReducedReal>> stress, correction;
  std::vector<Vec<2>> correction_shift = {vec(1, 0.5), vec(0.5, -1), vec(0, 0), vec(-1, 1)};  // the mixed correction's s
  std::vector<KernelScale> scales;  // cubic spline, h = 1, 2, 1, 0.5
};

// The pair (0, j)'s kernel value as the list bodies form it.
double pair_w(const Fields& f, std::uint32_t j) {
  return pair_average_value(
      pair_kernel_values(KernelType::Cubic, f.scales[kOwner], f.scales[j], std::sqrt(norm2(kParticles[kOwner].x - kParticles[j].x))));
}

Fields fields() {
  Fields f;
  for (const Particle& p : kParticles) {
    f.pos.push_back(p.x);
    f.vel.push_back(p.v);
    f.mass.push_back(p.m);
    f.inv_rho.push_back(1.0 / p.rho);
    f.volume.push_back(p.m / p.rho);
    f.log_rho.push_back(p.log_rho);
    f.Pr.push_back(p.Pr);
    Mat<2, ReducedReal> S, C;
    store(S, p.S);
    store(C, p.C);
    f.stress.push_back(S);
    f.correction.push_back(C);
  }
  for (double h : {1.0, 2.0, 1.0, 0.5}) f.scales.push_back(scale_of(KernelAt<CubicSpline, 2>(h)));
  return f;
}

// What a list adds to its owner and to the writable partners.
template <class T>
struct ListSums {
  T own{};
  std::vector<T> stored = std::vector<T>(kWritable);
};

// Eq. 8 and M (and with the mixed correction its sums) by the pair functions, pair by pair.
ListSums<GradientSums<2>> gradient_by_pair_terms(bool mixed) {
  const Fields f = fields();
  ListSums<GradientSums<2>> s;
  const Particle& i = kParticles[kOwner];
  for (std::size_t q = 0; q < kPartners.size(); ++q) {
    const std::uint32_t j = kPartners[q];
    const Particle& pj = kParticles[j];
    const Vec<2> dv = pj.v - i.v, dx = i.x - pj.x, g = kernel_gradient(dx, double{kFactors[q]});
    const GradientSums<2> products = gradient_pair_products(dv, dx);
    GradientSums<2> ti = gradient_term(double{kFactors[q]}, volume(pj), products);
    GradientSums<2> tj = gradient_term(double{kFactors[q]}, volume(i), products);
    if (mixed) {
      ti.shepard = shepard_term(pair_w(f, j), volume(pj), g, dv, dx);
      tj.shepard = shepard_term(pair_w(f, j), volume(i), -g, -dv, -dx);
    }
    accumulate(s.own, ti);
    if (j < kWritable) accumulate(s.stored[j], tj);
  }
  return s;
}

// What a list loop writes: its owner's sums, and the writable partners' as an evaluation keeps
// them (GradientSumsArray: V and M, the Shepard sums apart).
struct WrittenSums {
  GradientSums<2> own{};
  std::vector<GradientMoments<2>> stored = std::vector<GradientMoments<2>>(kWritable);
  std::vector<ShepardSums<2>> shepard = std::vector<ShepardSums<2>>(kWritable);
};

void expect_shepard(const ShepardSums<2>& got, const ShepardSums<2>& want, const std::string& what) {
  EXPECT_EQ(got.w, want.w) << what << " w";
  expect_vec(got.g, want.g, what + " g");
  expect_vec(got.w_dv, want.w_dv, what + " w_dv");
  expect_vec(got.w_dx, want.w_dx, what + " w_dx");
}

}  // namespace

TEST(PairTerms, GradientListSumsArePairTermSums) {
  const Fields f = fields();
  const ListSums<GradientSums<2>> want = gradient_by_pair_terms(false);
  // By hand from the three pairs' terms for 0 ((0, 1) above; (0, 2): V [[0, -1], [0, -1]],
  // M [[0, 0], [0, 1]]; (0, 3): V [[0.5, 0.5], [1.5, 1.5]], M [[1, 1], [1, 1]]).
  expect_mat(want.own.V, mat(-3.5, -2.5, -2.5, -1.5), "V_0 by hand");
  expect_mat(want.own.M, mat(9, 5, 5, 4), "M_0 by hand");
  for (const bool scalar : {true, false}) {
    WrittenSums got;
    const GradientListData<2> d{f.pos.data(), f.vel.data(), f.volume.data(), got.stored.data(), kWritable};
    if (scalar) add_gradient_list_scalar(d, kOwner, kPartners, kFactors, got.own);
    else add_gradient_list(d, kOwner, kPartners, kFactors, got.own);  // the vector path where the CPU has one
    const std::string path = scalar ? "scalar" : "dispatched";
    expect_mat(got.own.V, want.own.V, path + " V_0");
    expect_mat(got.own.M, want.own.M, path + " M_0");
    for (std::size_t j = 1; j < kWritable; ++j) {
      expect_mat(got.stored[j].V, want.stored[j].V, path + " V_" + std::to_string(j));
      expect_mat(got.stored[j].M, want.stored[j].M, path + " M_" + std::to_string(j));
    }
  }
}

// With the mixed correction's sums (the scalar loop, whatever the CPU).
TEST(PairTerms, MixedGradientListSumsArePairTermSums) {
  const Fields f = fields();
  const ListSums<GradientSums<2>> want = gradient_by_pair_terms(true);
  EXPECT_GT(want.own.shepard.w, 0.0);
  WrittenSums got;
  const GradientListData<2> d{f.pos.data(), f.vel.data(), f.volume.data(), got.stored.data(), kWritable,
                              f.scales.data(), KernelType::Cubic, got.shepard.data()};
  add_gradient_list(d, kOwner, kPartners, kFactors, got.own);
  expect_mat(got.own.V, want.own.V, "V_0");
  expect_mat(got.own.M, want.own.M, "M_0");
  expect_shepard(got.own.shepard, want.own.shepard, "0");
  for (std::size_t j = 1; j < kWritable; ++j) {
    expect_mat(got.stored[j].V, want.stored[j].V, "V_" + std::to_string(j));
    expect_mat(got.stored[j].M, want.stored[j].M, "M_" + std::to_string(j));
    expect_shepard(got.shepard[j], want.stored[j].shepard, std::to_string(j));
  }
}

namespace {

enum class Force { Conservative, ConservativePressure, CorrectedPressure, Consistent, ConsistentPressure, ConsistentMixed };

const char* name(Force form) {
  switch (form) {
    case Force::Conservative: return "conservative";
    case Force::ConservativePressure: return "conservative with pressure";
    case Force::CorrectedPressure: return "force-corrected with pressure";
    case Force::Consistent: return "consistent";
    case Force::ConsistentPressure: return "consistent with pressure";
    case Force::ConsistentMixed: return "consistent, mixed correction";
  }
  return "";
}

struct ForceSums {
  ListSums<Vec<2>> acc;
  ListSums<double> du;
};

// Eq. 6 (and pressure) by the pair functions, pair by pair, in each form.
ForceSums forces_by_pair_terms(Force form) {
  const bool pressure = form == Force::ConservativePressure || form == Force::CorrectedPressure ||
                        form == Force::ConsistentPressure;
  const bool consistent = form == Force::Consistent || form == Force::ConsistentPressure || form == Force::ConsistentMixed;
  const Fields fs = fields();
  ForceSums s;
  const Particle& i = kParticles[kOwner];
  for (std::size_t q = 0; q < kPartners.size(); ++q) {
    const std::uint32_t j = kPartners[q];
    const Particle& pj = kParticles[j];
    Vec<2> g = kernel_gradient(i.x - pj.x, double{kFactors[q]});
    if (form == Force::CorrectedPressure) g = corrected_pair_gradient(i.C, pj.C, g);
    Vec<2> f;
    if (consistent) {
      const PairTerms<Vec<2>> G =
          form == Force::ConsistentMixed
              ? mixed_corrected_gradients(i.C, pj.C, fs.correction_shift[kOwner], fs.correction_shift[j], pair_w(fs, j), g)
              : linear_corrected_gradients(i.C, pj.C, g);
      const PairTerms<Vec<2>> a = consistent_viscous_pair(i.S, pj.S, G, pj.log_rho - i.log_rho, i.m / i.rho, pj.m / pj.rho);
      s.acc.own += a.to_i;
      if (j < kWritable) s.acc.stored[j] += a.to_j;
    } else {
      f = conservative_viscous_pair(i.S, pj.S, 1.0 / i.rho, 1.0 / pj.rho, g);
    }
    if (pressure) {
      f -= pressure_pair(i.Pr, pj.Pr, g);
      const PairTerms<double> work = pressure_work_pair(i.Pr, pj.Pr, i.m, pj.m, i.v - pj.v, g);
      s.du.own += work.to_i;
      if (j < kWritable) s.du.stored[j] += work.to_j;
    }
    if (!consistent || pressure) {
      s.acc.own += f * pj.m;
      if (j < kWritable) s.acc.stored[j] -= f * i.m;
    }
  }
  return s;
}

// The list body's sums for one form (the partners' accelerations and energy rates from zero).
ForceSums forces_by_list(Force form, bool scalar) {
  const Fields f = fields();
  ForceSums s;
  std::vector<Vec<2>> acc(kParticles.size(), vec(0, 0));
  std::vector<double> du(kParticles.size(), 0.0);
  const bool pressure = form == Force::ConservativePressure || form == Force::CorrectedPressure ||
                        form == Force::ConsistentPressure;
  const bool consistent = form == Force::Consistent || form == Force::ConsistentPressure || form == Force::ConsistentMixed;
  ForceListData<2> d{f.pos.data(),     f.vel.data(),  f.stress.data(), f.correction.data(),
                     f.mass.data(),    f.inv_rho.data(), f.Pr.data(),  acc.data(),
                     du.data(),        kWritable,     pressure,        form == Force::CorrectedPressure,
                     f.log_rho.data(), consistent};
  if (consistent) d.volume = f.volume.data();
  if (form == Force::ConsistentMixed) d.correction_shift = f.correction_shift.data(), d.scales = f.scales.data();
  if (scalar) add_force_list_scalar(d, kOwner, kPartners, kFactors, s.acc.own, s.du.own);
  else add_force_list(d, kOwner, kPartners, kFactors, s.acc.own, s.du.own);
  EXPECT_EQ(acc[3], vec(0, 0)) << "a partner beyond the writable ones was written";
  for (std::size_t j = 0; j < kWritable; ++j) s.acc.stored[j] = acc[j], s.du.stored[j] = du[j];
  return s;
}

}  // namespace

TEST(PairTerms, ForceListSumsArePairTermSums) {
  // By hand from the three pairs' f for 0 ((0, 1) above; (0, 2): m_2 f = 4 (0.25, -0.625);
  // (0, 3): m_3 f = 0.5 (-5.75, -4)).
  expect_vec(forces_by_pair_terms(Force::Conservative).acc.own, vec(6.375, 5.5), "conservative a_0 by hand");
  for (const Force form : {Force::Conservative, Force::ConservativePressure, Force::CorrectedPressure, Force::Consistent,
                           Force::ConsistentPressure, Force::ConsistentMixed})
    for (const bool scalar : {true, false}) {
      const ForceSums want = forces_by_pair_terms(form), got = forces_by_list(form, scalar);
      const std::string what = std::string(scalar ? "scalar, " : "dispatched, ") + name(form);
      expect_vec(got.acc.own, want.acc.own, what + ": a_0");
      EXPECT_EQ(got.du.own, want.du.own) << what << ": du_0";
      for (std::size_t j = 1; j < kWritable; ++j) {
        expect_vec(got.acc.stored[j], want.acc.stored[j], what + ": a_" + std::to_string(j));
        EXPECT_EQ(got.du.stored[j], want.du.stored[j]) << what << ": du_" + std::to_string(j);
      }
    }
}

namespace {

Particles<2> particles() {
  Particles<2> p;
  p.resize(kParticles.size());
  for (std::size_t k = 0; k < kParticles.size(); ++k) {
    const Particle& q = kParticles[k];
    p.id[k] = k + 1;
    p.pos[k] = q.x;
    p.vel[k] = q.v;
    p.mass[k] = q.m;
    store(p.rho[k], q.rho);
    store(p.volume[k], q.m / q.rho);
    store(p.stress[k], q.S);
    store(p.correction[k], q.C);
  }
  return p;
}

// The pair source of one half list: particle 0's (the interface of neighbours/pair_lists.hpp).
struct OneList {
  mutable std::vector<float> F = kFactors;
  std::size_t writable() const { return kWritable; }
  void prepare_factors() const {}
  template <class Body>
  void for_each_list(Body&& f, FactorUse, std::string_view = {}, FarPairs = FarPairs::Last) const {
    f(kOwner, std::span<const std::uint32_t>(kPartners), std::span<float>(F));
  }
};

}  // namespace

// One h (h = 1): rho_i = m_i W(0) + the list's density terms, with kernel values w = {0.375, 0.25, 0.125}
// for the pairs (0, 1), (0, 2), (0, 3).
TEST(PairTerms, DensityListSumsArePairTermSums) {
  Particles<2> p = particles();
  const KernelAt<CubicSpline, 2> kern(1.0);
  ConstantHDensity<CubicSpline, 2> sums(p, kern, kWritable);
  const double w[3] = {0.375, 0.25, 0.125};
  sums.add_list(kOwner, kPartners, w);
  sums.finish();
  const double self = kern.W(0.0);
  const Particle &P2 = kParticles[2], &P3 = kParticles[3];
  // By hand: the list adds 1 (0.375) + 4 (0.25) + 0.5 (0.125) = 1.4375 to rho_0.
  const double list_0 = (density_term(P1.m, w[0]) + density_term(P2.m, w[1])) + density_term(P3.m, w[2]);
  EXPECT_EQ(list_0, 1.4375);
  const double want[3] = {density_term(P0.m, self) + list_0, density_term(P1.m, self) + density_term(P0.m, w[0]),
                          density_term(P2.m, self) + density_term(P0.m, w[1])};
  for (std::size_t k = 0; k < kWritable; ++k) {
    typename decltype(p.rho)::value_type rounded;
    store(rounded, want[k]);
    EXPECT_EQ(p.rho[k], rounded) << "rho_" << k;
  }
}

// The second half of the force-corrected heating: H_i = sum_j dv (x) C_j grad_i W_ij V_j, and
// du_i/dt += S_i : H_i / 2.
TEST(PairTerms, HeatingListSumsArePairTermSums) {
  Particles<2> p = particles();
  std::vector<Mat<2>> H;
  sum_corrected_heating_terms(p, OneList{}, H);
  std::vector<Mat<2>> want(kWritable);
  const Particle& i = kParticles[kOwner];
  for (std::size_t q = 0; q < kPartners.size(); ++q) {
    const std::uint32_t j = kPartners[q];
    const Particle& pj = kParticles[j];
    const Vec<2> dv = pj.v - i.v, dx = i.x - pj.x;
    accumulate(want[kOwner], corrected_heating_term(pj.C, double{kFactors[q]}, volume(pj), dv, dx));
    if (j < kWritable) accumulate(want[j], corrected_heating_term(i.C, double{kFactors[q]}, volume(i), dv, dx));
  }
  // By hand for 0: (0, 1) above, (0, 2): [[0, -1], [0, -1]], (0, 3): [[0.25, 1], [0.75, 3]].
  expect_mat(want[kOwner], mat(-4.75, -4, -4.25, -2), "H_0 by hand");
  ASSERT_GE(H.size(), kWritable);
  for (std::size_t k = 0; k < kWritable; ++k) expect_mat(H[k], want[k], "H_" + std::to_string(k));
  // And the rate it adds: S_0 : H_0 / 2 = (1 (-4.75) + 2 (-4) + 3 (-4.25) - 1 (-2)) / 2 = -11.75.
  std::fill(p.du_dt.begin(), p.du_dt.end(), 0.0);
  add_force_corrected_heating(p, OneList{}, H);
  EXPECT_EQ(p.du_dt[kOwner], -11.75);
}
