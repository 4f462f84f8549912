// The gradient and force sums of a half list (physics/list_sums.hpp) and its kernel-gradient factors
// (physics/list_factors.hpp) must come out of the vector paths bit for bit as out of the scalar
// loop: i's sum, every writable partner's sum, every factor, for lists of every length (remainders
// of every size), partners beyond the writable bound, coincident particles, partners at the
// kernels' breakpoints and equal velocities (zero differences, whose signs the sums must keep
// alike).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/vector_isa.hpp"
#include "physics/kernels.hpp"
#include "physics/list_factors.hpp"
#include "physics/list_sums.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

namespace {

constexpr std::size_t kParticles = 120, kWritable = 90;

struct Lists {
  std::vector<std::uint32_t> owner;
  std::vector<std::vector<std::uint32_t>> partners;
  std::vector<std::vector<float>> factors;
};

struct Fields {
  std::vector<Vec<2>> pos, vel;
  std::vector<double> volume, mass, inv_rho;
  std::vector<Mat<2, ReducedReal>> stress;
};

Fields random_fields() {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0), positive(0.5, 2.0);
  Fields f;
  for (std::size_t k = 0; k < kParticles; ++k) {
    f.pos.push_back(Vec<2>{{u(rng), u(rng)}});
    f.vel.push_back(Vec<2>{{u(rng), u(rng)}});
    f.volume.push_back(positive(rng));
    f.mass.push_back(positive(rng));
    f.inv_rho.push_back(positive(rng));
    Mat<2, ReducedReal> s;
    for (auto& c : s.c) c = static_cast<ReducedReal>(u(rng));
    f.stress.push_back(s);
  }
  f.pos[7] = f.pos[3];  // coincident with 3
  f.vel[8] = f.vel[3];  // moving with 3
  f.vel[9] = f.vel[3];
  return f;
}

// One list of every length 0..kParticles-1 (owner k % kParticles, distinct partners that are not
// the owner, in random order), random factors of both signs.
Lists random_lists() {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<float> u(-3.0f, 1.0f);
  Lists l;
  for (std::size_t n = 0; n + 1 < kParticles; ++n) {
    const auto i = static_cast<std::uint32_t>((n * 37 + 3) % kParticles);
    std::vector<std::uint32_t> all(kParticles);
    std::iota(all.begin(), all.end(), 0u);
    all.erase(all.begin() + i);
    std::shuffle(all.begin(), all.end(), rng);
    all.resize(n);
    if (i != 3 && n > 0) all[0] = 3;  // the coincident and co-moving partners in some lists
    if (i == 3 && n > 2) {
      all[0] = 7;
      all[1] = 8;
      all[2] = 9;
    }
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    std::shuffle(all.begin(), all.end(), rng);
    std::vector<float> F(all.size());
    for (float& x : F) x = u(rng);
    l.owner.push_back(i);
    l.partners.push_back(all);
    l.factors.push_back(F);
  }
  return l;
}

// Each list's sum for its owner (own) and what the lists added to the stored sums of the writable
// particles, which start at `start`.
// What the lists write: the partners' (stored, as an evaluation keeps them) and each owner's sums.
template <class T, class Own = T>
struct ListResults {
  std::vector<T> stored;
  std::vector<Own> own;
};

template <class Own = void, class T, class AddList>
auto sum_each_list(const Lists& l, const T& start, AddList&& add_list) {
  using O = std::conditional_t<std::is_void_v<Own>, T, Own>;
  ListResults<T, O> r;
  r.stored.assign(kWritable, start);
  for (std::size_t k = 0; k < l.owner.size(); ++k) {
    O own{};
    add_list(r.stored.data(), l.owner[k], l.partners[k], l.factors[k], own);
    r.own.push_back(own);
  }
  return r;
}

ListResults<GradientMoments<2>, GradientSums<2>> gradients(const Fields& f, const Lists& l) {
  return sum_each_list<GradientSums<2>>(l, GradientMoments<2>{}, [&](GradientMoments<2>* sums, std::uint32_t i, const auto& js,
                                                                     const auto& F, GradientSums<2>& own) {
    add_gradient_list({f.pos.data(), f.vel.data(), f.volume.data(), sums, kWritable}, i, js, F, own);
  });
}

ListResults<Vec<2>> forces(const Fields& f, const Lists& l) {
  return sum_each_list(l, Vec<2>{{0.25, -0.5}}, [&](Vec<2>* acc, std::uint32_t i, const auto& js, const auto& F, Vec<2>& own) {
    const ForceListData<2> d{f.pos.data(), f.vel.data(), f.stress.data(), nullptr, f.mass.data(), f.inv_rho.data(),
                             nullptr, acc, nullptr, kWritable, false, false};
    double du = 0.0;
    add_force_list(d, i, js, F, own, du);
    EXPECT_EQ(du, 0.0);  // no pressure, no work
  });
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

// The list sums of run() on the scalar path, after checking that every vector path gives them bit
// for bit (i's sums and the partners').
template <class Run>
auto scalar_after_every_path_agrees(Run run, const std::string& what = "") {
  const auto scalar = test::on_path(VectorIsa::baseline, run);
  for (const VectorIsa isa : test::vector_paths()) {
    const auto vector = test::on_path(isa, run);
    EXPECT_TRUE(same_bits(vector.own, scalar.own)) << vector_isa_name(isa) << what;
    EXPECT_TRUE(same_bits(vector.stored, scalar.stored)) << vector_isa_name(isa) << what;
  }
  return scalar;
}

// Not vacuous: the second list (one partner) sums exactly that pair's terms (pair_terms.hpp).
template <class F, int D>
bool sums_of_the_pair_terms(const F& f, const Lists& l, const GradientSums<D>& got) {
  GradientSums<D> expected{};
  const std::uint32_t i = l.owner[1], j = l.partners[1][0];
  accumulate(expected, gradient_term(static_cast<double>(l.factors[1][0]), f.volume[j],
                                     gradient_pair_products(f.vel[j] - f.vel[i], f.pos[i] - f.pos[j])));
  return std::memcmp(&got, &expected, sizeof expected) == 0;
}

}  // namespace

TEST(ListSums, GradientPathsAgree) {
  if (test::vector_paths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the scalar path runs";
  const Fields f = random_fields();
  const Lists l = random_lists();
  const auto scalar = scalar_after_every_path_agrees([&] { return gradients(f, l); });
  EXPECT_TRUE(sums_of_the_pair_terms(f, l, scalar.own[1]));
}

TEST(ListSums, ForcePathsAgree) {
  if (test::vector_paths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the scalar path runs";
  const Fields f = random_fields();
  const Lists l = random_lists();
  const auto scalar = scalar_after_every_path_agrees([&] { return forces(f, l); });
  EXPECT_NE(scalar.stored[0], (Vec<2>{{0.25, -0.5}}));  // the partners' accelerations were written
}

namespace {

template <class K>
std::vector<std::vector<float>> factors(const Fields& f, const std::vector<KernelSlope>& slopes, const Lists& l) {
  std::vector<std::vector<float>> all;
  for (std::size_t k = 0; k < l.owner.size(); ++k) {
    std::vector<float> F(l.partners[k].size());
    form_list_factors<K>(f.pos.data(), slopes.data(), l.owner[k], l.partners[k], F);
    all.push_back(F);
  }
  return all;
}

template <class K>
void check_factor_paths_agree(VectorIsa isa) {
  Fields f = random_fields();
  std::vector<KernelSlope> slopes;
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> inv_h(0.4, 3.0), dw_norm(0.1, 2.0);
  for (std::size_t k = 0; k < kParticles; ++k) slopes.push_back({inv_h(rng), dw_norm(rng)});
  slopes[3].inv_h = 1.0;  // partners at q = 1 and q = 2 of particle 3's kernel
  f.pos[8] = f.pos[3] + Vec<2>{{1.0, 0.0}};
  f.pos[9] = f.pos[3] + Vec<2>{{0.0, 2.0}};
  const Lists l = random_lists();
  const auto vector = test::on_path(isa, [&] { return factors<K>(f, slopes, l); });
  const auto scalar = test::on_path(VectorIsa::baseline, [&] { return factors<K>(f, slopes, l); });
  for (std::size_t k = 0; k < l.owner.size(); ++k) {
    ASSERT_TRUE(same_bits(vector[k], scalar[k])) << vector_isa_name(isa) << ", " << K::name << ", list " << k;
    for (std::size_t q = 0; q < l.partners[k].size(); ++q) {  // and both are the pair average
      const std::uint32_t i = l.owner[k], j = l.partners[k][q];
      ASSERT_EQ(vector[k][q], static_cast<float>(pair_average_factor<K>(slopes[i], slopes[j], norm(f.pos[i] - f.pos[j]))));
    }
  }
}

}  // namespace

TEST(ListSums, FactorPathsAgree) {
  if (test::vector_paths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the scalar path runs";
  for (const VectorIsa isa : test::vector_paths()) {
    check_factor_paths_agree<CubicSpline>(isa);
    check_factor_paths_agree<WendlandC2>(isa);
    check_factor_paths_agree<WendlandC4>(isa);
  }
}

namespace {

// The factors of pair loops that keep no slopes (factors_from_h: slopes made from h, squared
// distances given), on every vector path, bit for bit those of form_list_factors from slopes bound
// from the same h on the scalar path.
template <class K, int D>
void check_factors_from_h(VectorIsa isa) {
  const Fields f = random_fields();
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> hs(0.3, 2.5);
  std::vector<double> h;
  std::vector<KernelSlope> slopes;
  for (std::size_t k = 0; k < kParticles; ++k) {
    h.push_back(hs(rng));
    slopes.push_back(slope_of(KernelAt<K, D>(h.back())));
  }
  const Lists l = random_lists();
  const auto bound = test::on_path(VectorIsa::baseline, [&] { return factors<K>(f, slopes, l); });
  const auto from_h = test::on_path(isa, [&] {
    std::vector<std::vector<float>> all;
    for (std::size_t k = 0; k < l.owner.size(); ++k) {
      const auto& js = l.partners[k];
      std::vector<double> r2(js.size() + 8, 0.0);  // room for whole vectors of eight
      for (std::size_t q = 0; q < js.size(); ++q) r2[q] = norm2(f.pos[l.owner[k]] - f.pos[js[q]]);
      std::vector<float> F(js.size());
      factors_from_h<K, D>(h[l.owner[k]], h.data(), js, r2.data(), F);
      all.push_back(F);
    }
    return all;
  });
  for (std::size_t k = 0; k < l.owner.size(); ++k)
    ASSERT_TRUE(same_bits(from_h[k], bound[k])) << vector_isa_name(isa) << ", " << K::name << ", " << D << "D, list " << k;
}

}  // namespace

TEST(ListSums, FactorsFromSmoothingLengthsEqualBoundSlopes) {
  std::vector<VectorIsa> paths = test::vector_paths();
  paths.push_back(VectorIsa::baseline);
  for (const VectorIsa isa : paths) {
    check_factors_from_h<CubicSpline, 2>(isa);
    check_factors_from_h<WendlandC2, 2>(isa);
    check_factors_from_h<WendlandC4, 2>(isa);
    check_factors_from_h<CubicSpline, 3>(isa);
    check_factors_from_h<WendlandC2, 3>(isa);
    check_factors_from_h<WendlandC4, 3>(isa);
  }
}

namespace {

// 3D fields with pressure and the artificial viscosity's inputs.
struct Fields3 {
  std::vector<Vec<3>> pos, vel;
  std::vector<double> volume, mass, inv_rho, p_over_rho2, sound_speed, limiter, alpha;
  std::vector<Mat<3, ReducedReal>> stress;
};

Fields3 random_fields_3d() {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0), positive(0.5, 2.0);
  Fields3 f;
  for (std::size_t k = 0; k < kParticles; ++k) {
    f.pos.push_back(Vec<3>{{u(rng), u(rng), u(rng)}});
    f.vel.push_back(Vec<3>{{u(rng), u(rng), u(rng)}});
    for (auto* x : {&f.volume, &f.mass, &f.inv_rho, &f.p_over_rho2, &f.sound_speed, &f.limiter, &f.alpha})
      x->push_back(positive(rng));
    Mat<3, ReducedReal> s;
    for (auto& c : s.c) c = static_cast<ReducedReal>(u(rng));
    f.stress.push_back(s);
  }
  f.pos[7] = f.pos[3];  // coincident with 3
  f.vel[8] = f.vel[3];  // moving with 3
  f.vel[9] = f.vel[3];
  return f;
}

ListResults<GradientMoments<3>, GradientSums<3>> gradients_3d(const Fields3& f, const Lists& l) {
  return sum_each_list<GradientSums<3>>(l, GradientMoments<3>{}, [&](GradientMoments<3>* sums, std::uint32_t i, const auto& js,
                                                                     const auto& F, GradientSums<3>& own) {
    add_gradient_list({f.pos.data(), f.vel.data(), f.volume.data(), sums, kWritable}, i, js, F, own);
  });
}

// What a force list with pressure writes: the acceleration, energy rate and signal speed.
template <int D>
struct ForceOut {
  Vec<D> a{};
  double du = 0.0, signal = 0.0;
};
using ForceOut3 = ForceOut<3>;

ListResults<ForceOut3> pressure_forces_3d(const Fields3& f, const Lists& l, bool viscosity, bool limiter) {
  ForceOut3 start;
  start.a = Vec<3>{{0.25, -0.5, 0.125}};
  start.du = 0.75;
  start.signal = 0.5;
  ListResults<ForceOut3> r;
  r.stored.assign(kWritable, start);
  std::vector<Vec<3>> acc(kWritable, start.a);
  std::vector<double> du_dt(kParticles, start.du), signal(kParticles, start.signal);
  for (std::size_t k = 0; k < l.owner.size(); ++k) {
    ForceListData<3> d{f.pos.data(), f.vel.data(), f.stress.data(), nullptr, f.mass.data(), f.inv_rho.data(),
                       f.p_over_rho2.data(), acc.data(), du_dt.data(), kWritable, true, false};
    if (viscosity) {
      d.sound_speed = f.sound_speed.data();
      d.limiter = limiter ? f.limiter.data() : nullptr;
      d.av_alpha = f.alpha.data();
      d.av_beta = 2.0;
      d.signal_speed = signal.data();
    }
    ForceOut3 own;
    add_force_list(d, l.owner[k], l.partners[k], l.factors[k], own.a, own.du);
    own.signal = signal[l.owner[k]];
    r.own.push_back(own);
  }
  for (std::size_t j = 0; j < kWritable; ++j) r.stored[j] = {acc[j], du_dt[j], signal[j]};
  return r;
}

}  // namespace

TEST(ListSums, GradientPathsAgreeIn3D) {
  if (test::vector_paths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the scalar path runs";
  const Fields3 f = random_fields_3d();
  const Lists l = random_lists();
  const auto scalar = scalar_after_every_path_agrees([&] { return gradients_3d(f, l); });
  EXPECT_TRUE(sums_of_the_pair_terms(f, l, scalar.own[1]));
}

// With pressure, with and without the artificial viscosity and its limiter: the accelerations,
// energy rates and signal speeds of both paths agree bit for bit.
TEST(ListSums, PressureForcePathsAgreeIn3D) {
  if (test::vector_paths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the scalar path runs";
  const Fields3 f = random_fields_3d();
  const Lists l = random_lists();
  for (const auto& [viscosity, limiter] : {std::pair{false, false}, std::pair{true, false}, std::pair{true, true}}) {
    const auto scalar = scalar_after_every_path_agrees([&] { return pressure_forces_3d(f, l, viscosity, limiter); },
                                                       " viscosity " + std::to_string(viscosity) + " limiter " + std::to_string(limiter));
    EXPECT_NE(scalar.stored[0].a[2], 0.125);  // the partners' accelerations were written
    EXPECT_NE(scalar.stored[0].du, 0.75);
    if (viscosity) EXPECT_NE(scalar.stored[0].signal, 0.5);
  }
}

namespace {

// What the consistent divergence reads besides the fields: random correction matrices and ln rho.
template <int D>
std::pair<std::vector<Mat<D, ReducedReal>>, std::vector<double>> random_consistent_inputs(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Mat<D, ReducedReal>> correction(kParticles);
  std::vector<double> log_rho(kParticles);
  for (std::size_t k = 0; k < kParticles; ++k) {
    for (auto& c : correction[k].c) c = static_cast<ReducedReal>(u(rng));
    log_rho[k] = u(rng);
  }
  return {correction, log_rho};
}

// The consistent divergence with pressure: both paths' accelerations and pressure work agree bit
// for bit, with and without an energy rate to write, and the one-partner list gives the viscous pair
// term plus the pressure's, by the pair functions (one pair by hand).
template <int D, class FieldsD>
void check_consistent_force_with_pressure(const FieldsD& f, const std::vector<double>& p_over_rho2, std::uint64_t seed) {
  const Lists l = random_lists();
  const auto [correction, log_rho] = random_consistent_inputs<D>(seed);
  const double initial[3] = {0.25, -0.5, 0.125};  // what the accelerations hold before the sums
  Vec<D> start_a;
  for (int c = 0; c < D; ++c) start_a[c] = initial[c];
  for (const bool energy : {true, false}) {
    const auto run = [&] {
      ListResults<ForceOut<D>> r;
      std::vector<Vec<D>> acc(kWritable, start_a);
      std::vector<double> du_dt(kWritable, 0.75);
      for (std::size_t k = 0; k < l.owner.size(); ++k) {
        ForceListData<D> d{f.pos.data(), f.vel.data(), f.stress.data(), correction.data(), f.mass.data(), f.inv_rho.data(),
                           p_over_rho2.data(), acc.data(), energy ? du_dt.data() : nullptr, kWritable, true, false};
        d.log_rho = log_rho.data();
        d.consistent = true;
        d.volume = f.volume.data();
        ForceOut<D> own;
        add_force_list(d, l.owner[k], l.partners[k], l.factors[k], own.a, own.du);
        r.own.push_back(own);
      }
      for (std::size_t j = 0; j < kWritable; ++j) r.stored.push_back({acc[j], du_dt[j], 0.0});
      return r;
    };
    const auto scalar = scalar_after_every_path_agrees(run, energy ? " with energy" : " without energy");
    EXPECT_NE(scalar.stored[0].a, start_a);
    EXPECT_NE(scalar.stored[0].a[D - 1], start_a[D - 1]);
    EXPECT_EQ(scalar.stored[0].du != 0.75, energy);  // the partners' energy rates only where kept
    const std::uint32_t i = l.owner[1], j = l.partners[1][0];
    const Vec<D> g = kernel_gradient(f.pos[i] - f.pos[j], static_cast<double>(l.factors[1][0]));
    Vec<D> expected = consistent_viscous_pair(as_double(f.stress[i]), as_double(f.stress[j]),
                                              linear_corrected_gradients(as_double(correction[i]), as_double(correction[j]), g),
                                              log_rho[j] - log_rho[i], f.volume[i], f.volume[j])
                          .to_i;
    expected += (Vec<D>{} - pressure_pair(p_over_rho2[i], p_over_rho2[j], g)) * f.mass[j];
    EXPECT_EQ(std::memcmp(&scalar.own[1].a, &expected, sizeof expected), 0);
    EXPECT_EQ(scalar.own[1].du, pressure_work_pair(p_over_rho2[i], p_over_rho2[j], f.mass[i], f.mass[j], f.vel[i] - f.vel[j], g).to_i);
  }
}

}  // namespace

// The consistent divergence with pressure in 3D (the default there with adaptive h).
TEST(ListSums, ConsistentForceWithPressurePathsAgreeIn3D) {
  if (test::vector_paths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the scalar path runs";
  const Fields3 f = random_fields_3d();
  check_consistent_force_with_pressure<3>(f, f.p_over_rho2, 23);
}

// The consistent divergence (the 2D default with adaptive h): both paths' accelerations agree bit
// for bit, and they are those of the pair function (one pair by hand).
TEST(ListSums, ConsistentForcePathsAgree) {
  if (test::vector_paths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the scalar path runs";
  const Fields f = random_fields();
  const Lists l = random_lists();
  const auto [correction, log_rho] = random_consistent_inputs<2>(17);
  const auto consistent = [&] {
    return sum_each_list(l, Vec<2>{{0.25, -0.5}}, [&](Vec<2>* acc, std::uint32_t i, const auto& js, const auto& F, Vec<2>& own) {
      ForceListData<2> d{f.pos.data(), f.vel.data(), f.stress.data(), correction.data(), f.mass.data(), f.inv_rho.data(),
                         nullptr, acc, nullptr, kWritable, false, false};
      d.log_rho = log_rho.data();
      d.consistent = true;
      d.volume = f.volume.data();
      double du = 0.0;
      add_force_list(d, i, js, F, own, du);
    });
  };
  const auto scalar = scalar_after_every_path_agrees(consistent);
  EXPECT_NE(scalar.stored[0], (Vec<2>{{0.25, -0.5}}));
  const std::uint32_t i = l.owner[1], j = l.partners[1][0];
  const Vec<2> g = kernel_gradient(f.pos[i] - f.pos[j], static_cast<double>(l.factors[1][0]));
  const Mat<2> Si = as_double(f.stress[i]), Sj = as_double(f.stress[j]);
  const Vec<2> expected = consistent_viscous_pair(Si, Sj, linear_corrected_gradients(as_double(correction[i]), as_double(correction[j]), g),
                                                  log_rho[j] - log_rho[i], f.volume[i], f.volume[j])
                              .to_i;
  EXPECT_EQ(std::memcmp(&scalar.own[1], &expected, sizeof expected), 0);
}

// The consistent divergence with pressure in 2D (the cold ring, configs/ring_cold.toml).
TEST(ListSums, ConsistentForceWithPressurePathsAgree) {
  if (test::vector_paths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the scalar path runs";
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> positive(0.5, 2.0);
  std::vector<double> p_over_rho2(kParticles);
  for (double& x : p_over_rho2) x = positive(rng);
  check_consistent_force_with_pressure<2>(random_fields(), p_over_rho2, 19);
}

// The scatter density's pair terms (the cold ring's extra loop): both paths' sums agree bit for bit
// for every kernel (the cubic one has an AVX-512 loop), with partners at the kernel's breakpoints
// q = 1 and q = 2 of either particle and a coincident one, and the one-partner list gives the pair's
// term m_j W(r, h_j).
TEST(ListSums, ScatterPathsAgree) {
  if (test::vector_paths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the scalar path runs";
  Fields f = random_fields();
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> h(0.3, 1.5);
  std::vector<double> hs(kParticles);
  for (double& x : hs) x = h(rng);
  hs[3] = 0.5;  // partners at q = 1 and q = 2 of particle 3's kernel
  f.pos[8] = f.pos[3] + Vec<2>{{0.5, 0.0}};
  f.pos[9] = f.pos[3] + Vec<2>{{0.0, 1.0}};
  const Lists l = random_lists();
  for (const KernelType kernel : {KernelType::Cubic, KernelType::WendlandC2, KernelType::WendlandC4}) {
    std::vector<KernelScale> scales(kParticles);
    with_kernel(kernel, [&](auto k) {
      for (std::size_t q = 0; q < kParticles; ++q) scales[q] = scale_of(KernelAt<decltype(k), 2>(hs[q]));
    });
    const auto run = [&] {
      return sum_each_list(l, 0.5, [&](double* sums, std::uint32_t i, const auto& js, const auto&, double& own) {
        add_scatter_list(ScatterListData<2>{f.pos.data(), f.mass.data(), scales.data(), sums, kWritable, kernel}, i, js, own);
      });
    };
    const auto scalar = scalar_after_every_path_agrees(run, " kernel " + std::to_string(static_cast<int>(kernel)));
    EXPECT_NE(scalar.stored[0], 0.5);
    const std::uint32_t i = l.owner[1], j = l.partners[1][0];
    const double expected = with_kernel(kernel, [&](auto k) {
      return f.mass[j] * KernelAt<decltype(k), 2>(hs[j]).W(norm(f.pos[i] - f.pos[j]));
    });
    EXPECT_DOUBLE_EQ(scalar.own[1], expected);
  }
}
