// The candidate scan (neighbours/candidate_scan.hpp): its vector paths (AVX2 and AVX-512 in 2D,
// AVX-512 in 3D, those the CPU has) must give the scalar path's candidates and squared distances bit
// for bit, at the radius too, for rows of every length (partial last rounds), and so must whole
// neighbour lists built with either.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <tuple>
#include <random>
#include <vector>

#include "core/vector_isa.hpp"
#include "neighbours/candidate_scan.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "neighbours/pair_lists.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

namespace {

struct Scanned {
  std::vector<std::uint32_t> idx;
  std::vector<double> d2;
};

template <int D>
Scanned scan(VectorIsa isa, const std::vector<std::uint32_t>& js, const std::vector<Vec<D>>& xs, std::uint32_t s0,
             std::uint32_t s1, const ScanTarget<D>& t) {
  return test::on_path(isa, [&] {
    Scanned r;
    r.idx.assign(s1 - s0 + kScanSlack, 0);
    r.d2.assign(s1 - s0 + kScanSlack, 0.0);
    const std::size_t n = scan_candidates(js.data(), xs.data(), s0, s1, t, r.idx.data(), r.d2.data());
    r.idx.resize(n);
    r.d2.resize(n);
    return r;
  });
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

// Positions on a lattice of 1/8 (cells -c..c per axis), so many squared distances equal r2 exactly
// (1/8 and r2 = 1/4 are exact); candidates are accepted only below r2. Every row length (partial
// last rounds), reading past the range's end or not.
template <int D>
void check_scan_paths_agree(VectorIsa isa, int c, const std::vector<ScanTarget<D>>& targets) {
  std::mt19937_64 rng(D == 2 ? 11 : 13);
  std::uniform_int_distribution<int> cell(-c, c);
  std::vector<Vec<D>> xs(64);
  std::vector<std::uint32_t> js(64);
  for (std::size_t s = 0; s < xs.size(); ++s) {
    for (int k = 0; k < D; ++k) xs[s][k] = 0.125 * cell(rng);
    js[s] = static_cast<std::uint32_t>((s * 37) % 64);
  }
  std::size_t at_radius = 0, accepted = 0;
  for (const ScanTarget<D>& t : targets) {
    for (std::uint32_t s0 = 0; s0 < 9; ++s0)
      for (std::uint32_t s1 = s0; s1 <= 40; ++s1)
        // The vector scans may read the slots after s1 (all 64 exist), or only up to s1.
        for (const std::uint32_t readable : {std::uint32_t{64}, s1}) {
          ScanTarget<D> target = t;
          target.readable = readable;
          const Scanned v = scan(isa, js, xs, s0, s1, target), s = scan(VectorIsa::baseline, js, xs, s0, s1, target);
          ASSERT_EQ(v.idx, s.idx) << vector_isa_name(isa) << ", " << D << "D, slots " << s0 << "-" << s1 << " of " << readable;
          ASSERT_TRUE(same_bits(v.d2, s.d2)) << vector_isa_name(isa) << ", " << D << "D, slots " << s0 << "-" << s1 << " of " << readable;
          accepted += s.idx.size();
        }
    for (std::size_t s = 0; s < xs.size(); ++s) at_radius += norm2(xs[s] - t.x) == t.r2;
  }
  EXPECT_GE(at_radius, 3u);  // the boundary case is exercised
  EXPECT_GT(accepted, 1000u);
}

// Dropping beyond a smaller radius, in place, for every length, entries exactly at it included.
void check_keep_paths_agree(VectorIsa isa) {
  std::vector<double> d2(40);
  for (std::size_t k = 0; k < d2.size(); ++k) d2[k] = 0.0625 * static_cast<double>(k % 7);
  for (std::size_t n = 0; n <= d2.size(); ++n) {
    std::vector<std::uint32_t> a(n + kScanSlack), b(n + kScanSlack);
    for (std::size_t k = 0; k < n; ++k) a[k] = b[k] = static_cast<std::uint32_t>(100 + k);
    const std::size_t kept_vector = test::on_path(isa, [&] { return keep_within(a.data(), d2.data(), n, 0.25); });
    const std::size_t kept_scalar = test::on_path(VectorIsa::baseline, [&] { return keep_within(b.data(), d2.data(), n, 0.25); });
    ASSERT_EQ(kept_vector, kept_scalar) << vector_isa_name(isa) << ", n = " << n;
    a.resize(kept_vector);
    b.resize(kept_scalar);
    ASSERT_EQ(a, b) << vector_isa_name(isa) << ", n = " << n;
  }
}

// Dropping the candidates whose own support covers the pair, in place, for every length: the
// partners' h loaded by index, entries exactly at a support kept (r^2 = (2 h)^2 is outside it), the
// entries past n left as they were (pair_scan.hpp keeps its later candidates there), and the
// kept entries the brute-force ones.
void check_beyond_supports(VectorIsa isa) {
  std::vector<double> h(200);
  for (std::size_t j = 0; j < h.size(); ++j) h[j] = 0.125 * static_cast<double>(1 + j % 5);  // 2 h = 0.25 .. 1.25
  for (std::size_t n = 0; n <= 40; ++n) {
    std::vector<std::uint32_t> idx(n + kScanSlack);
    std::vector<double> d2(n + kScanSlack);
    for (std::size_t k = 0; k < idx.size(); ++k) {
      idx[k] = static_cast<std::uint32_t>((37 * k + 11) % h.size());
      d2[k] = 0.0625 * static_cast<double>(k % 13);  // hits (2 h)^2 = 0.0625, 0.25, 0.5625, 1 exactly
    }
    std::vector<std::uint32_t> expected_idx;
    std::vector<double> expected_d2;
    for (std::size_t k = 0; k < n; ++k)
      if (d2[k] >= 4.0 * h[idx[k]] * h[idx[k]]) {
        expected_idx.push_back(idx[k]);
        expected_d2.push_back(d2[k]);
      }
    const std::vector<std::uint32_t> tail_idx(idx.begin() + static_cast<std::ptrdiff_t>(n), idx.end());
    const std::vector<double> tail_d2(d2.begin() + static_cast<std::ptrdiff_t>(n), d2.end());
    const std::size_t kept = test::on_path(isa, [&] { return keep_beyond_supports(idx.data(), d2.data(), n, h.data()); });
    ASSERT_EQ(kept, expected_idx.size()) << vector_isa_name(isa) << ", n = " << n;
    ASSERT_TRUE(std::equal(expected_idx.begin(), expected_idx.end(), idx.begin())) << vector_isa_name(isa) << ", n = " << n;
    ASSERT_TRUE(std::equal(expected_d2.begin(), expected_d2.end(), d2.begin())) << vector_isa_name(isa) << ", n = " << n;
    ASSERT_TRUE(std::equal(tail_idx.begin(), tail_idx.end(), idx.begin() + static_cast<std::ptrdiff_t>(n)))
        << vector_isa_name(isa) << ", n = " << n << ": an entry past n was written";
    ASSERT_TRUE(std::equal(tail_d2.begin(), tail_d2.end(), d2.begin() + static_cast<std::ptrdiff_t>(n)))
        << vector_isa_name(isa) << ", n = " << n << ": a distance past n was written";
  }
}

}  // namespace

TEST(CandidateScan, VectorAndScalarPathsAgree) {
  if (test::vector_paths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the scalar path runs";
  for (const VectorIsa isa : test::vector_paths()) {
    check_scan_paths_agree<2>(isa, 6, {ScanTarget<2>{Vec<2>{{0.0, 0.0}}, 0.25, UINT32_MAX, UINT32_MAX},
                                       ScanTarget<2>{Vec<2>{{0.125, -0.25}}, 0.25, 5, UINT32_MAX},
                                       ScanTarget<2>{Vec<2>{{0.1, 0.3}}, 0.4, 9, 32}});
    check_scan_paths_agree<3>(isa, 4, {ScanTarget<3>{Vec<3>{{0.0, 0.0, 0.0}}, 0.25, UINT32_MAX, UINT32_MAX},
                                       ScanTarget<3>{Vec<3>{{0.125, -0.25, 0.125}}, 0.25, 5, UINT32_MAX},
                                       ScanTarget<3>{Vec<3>{{0.1, 0.3, -0.2}}, 0.4, 9, 32}});
  }
}

TEST(CandidateScan, KeepWithinPathsAgree) {
  if (test::vector_paths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the scalar path runs";
  for (const VectorIsa isa : test::vector_paths()) check_keep_paths_agree(isa);
}

// Where a gather list meets its particle and which earlier partners lack it: lists of every length
// (the last round of eight masks its loads), meeting points anywhere in them, partners exactly at
// their support's edge (|x_i - x_j| = 2 h_j, which the partner's list lacks) and index limits.
// (AVX2 runs the scalar code here: only the AVX-512 path differs.)
TEST(CandidateScan, EarlierPartnersAgree) {
  if (cpu_vector_isa() < VectorIsa::avx512) GTEST_SKIP() << "this CPU has no AVX-512: only the scalar path runs";
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> cell(-4, 4);
  const std::size_t n = 48;
  std::vector<Vec<2>> pos(n);
  std::vector<double> h(n);
  std::vector<std::uint32_t> slot(n);
  for (std::size_t j = 0; j < n; ++j) {
    pos[j] = Vec<2>{{0.125 * cell(rng), 0.125 * cell(rng)}};
    h[j] = 0.0625 * static_cast<double>(1 + j % 6);  // 2 h_j on the same 1/8 lattice: exact edges
    slot[j] = static_cast<std::uint32_t>((j * 29) % n);
  }
  pos[0] = Vec<2>{{0.0, 0.0}};  // exactly 2 h_j from x_i = (1/8, 0): h_0 = h_6 = 1/16
  pos[6] = Vec<2>{{0.125, 0.125}};
  std::size_t lacking_total = 0, at_edge = 0;
  for (std::size_t len = 0; len <= 40; ++len) {
    std::vector<std::uint32_t> js(len);
    for (std::size_t k = 0; k < len; ++k) js[k] = static_cast<std::uint32_t>((k * 7 + len) % n);
    std::sort(js.begin(), js.end(), [&](std::uint32_t a, std::uint32_t b) { return slot[a] < slot[b]; });
    for (const std::uint32_t slot_i : {0u, 5u, 17u, 30u, 47u, 48u})
      for (const std::uint32_t limit : {UINT32_MAX, 20u}) {
        const Vec<2> xi{{0.125, 0.0}};
        std::vector<std::uint32_t> a(len + kScanSlack), b(len + kScanSlack);
        const EarlierPartners v = earlier_partners(js.data(), len, slot_i, slot.data(), xi, pos.data(), h.data(), limit, a.data());
        const EarlierPartners s = test::on_path(VectorIsa::baseline, [&] {
          return earlier_partners(js.data(), len, slot_i, slot.data(), xi, pos.data(), h.data(), limit, b.data());
        });
        ASSERT_EQ(v.count, s.count) << len << " " << slot_i;
        ASSERT_EQ(v.lacking, s.lacking) << len << " " << slot_i;
        a.resize(v.lacking);
        b.resize(s.lacking);
        ASSERT_EQ(a, b) << len << " " << slot_i;
        lacking_total += s.lacking;
      }
  }
  for (std::size_t j = 0; j < n; ++j) at_edge += norm2(Vec<2>{{0.125, 0.0}} - pos[j]) == 4.0 * h[j] * h[j];
  EXPECT_GT(lacking_total, 100u);
  EXPECT_GE(at_edge, 2u);  // the edge case is exercised
}

// Gather lists with the h solve's settle (distances passed on, candidates beyond the kept radius
// dropped) and half lists, each built with both paths.
TEST(CandidateScan, SameListsWithEitherPath) {
  if (test::vector_paths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the scalar path runs";
  const auto p = test::random_particles<2>(5000, 12, true);
  const auto grid = build_cell_grid(p.pos, p.id, 0.02);
  std::vector<double> radius(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) radius[i] = 0.03 + 0.02 * static_cast<double>(i % 5) / 5.0;
  const SettleRadius settle = [](std::size_t, std::span<const std::uint32_t> cand, std::span<const double> d2, double searched) {
    EXPECT_EQ(cand.size(), d2.size());
    return 0.8 * searched;  // drop the outer candidates
  };
  auto build = [&](VectorIsa isa) {
    limit_vector_isa(isa);
    NeighbourLists gather, half;
    build_settled_neighbour_lists(grid, p.pos, radius, settle, gather, p.size());
    std::vector<std::uint32_t> slot(p.size());
    for (std::size_t s = 0; s < grid.sorted.size(); ++s) slot[grid.sorted[s]] = static_cast<std::uint32_t>(s);
    build_half_neighbour_lists(grid, p.pos, 0.03, slot, p.size() / 2, grid.sorted, half);  // lists in cell order
    PairLists from_gather;  // half lists assembled from the gather lists, supports h = radius / 2
    std::vector<double> h(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) h[i] = 0.4 * radius[i];  // the settled radius, 0.8 x searched
    build_tile_order(grid, 4, p.size() * 3 / 4, from_gather, TileWrites::AllNeighbours);
    NeighbourLists consumed = gather;  // (the half lists are made inside it)
    build_half_lists_from_gather(consumed, p.pos, h, from_gather);
    from_gather.near.join();  // held by from_gather itself, which is returned
    limit_vector_isa(VectorIsa::avx512);
    return std::tuple{gather, half, from_gather};
  };
  const auto [gs, hs, ps] = build(VectorIsa::baseline);
  EXPECT_GT(ps.total(), 5 * p.size());
  EXPECT_GT(gs.total(), 10 * p.size());
  EXPECT_GT(hs.total(), 5 * p.size());
  for (const VectorIsa isa : test::vector_paths()) {
    SCOPED_TRACE(vector_isa_name(isa));
    const auto [gv, hv, pv] = build(isa);
    EXPECT_EQ(pv.near.offsets, ps.near.offsets);
    EXPECT_EQ(pv.near.index, ps.near.index);
    EXPECT_EQ(pv.far.offsets, ps.far.offsets);
    EXPECT_EQ(pv.far.index, ps.far.index);
    EXPECT_EQ(gv.offsets, gs.offsets);
    EXPECT_EQ(gv.index, gs.index);
    EXPECT_EQ(hv.offsets, hs.offsets);
    EXPECT_EQ(hv.index, hs.index);
  }
}

TEST(CandidateScan, KeepBeyondSupportsOnEveryPath) {
  check_beyond_supports(VectorIsa::baseline);
  for (const VectorIsa isa : test::vector_paths()) check_beyond_supports(isa);
}
