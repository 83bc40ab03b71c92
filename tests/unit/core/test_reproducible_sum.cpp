// parallel::ReproducibleSum and reproducible_sum (src/parallel/reproducible_sum.hpp): the same
// bits for any order, split and thread count, against an exact reference sum computed by
// Shewchuk's algorithm (J. R. Shewchuk, "Adaptive precision floating-point arithmetic and fast
// robust geometric predicates", Discrete Comput. Geom. 18, 1997: the non-overlapping partials
// that Python's math.fsum keeps), within the sum's own error bound plus one rounding.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "parallel/comm.hpp"
#include "parallel/reproducible_sum.hpp"

namespace {

using crater::Index;
using crater::Real;
using crater::parallel::ReproducibleSum;

// The exactly rounded sum (Shewchuk's partials, then their sum from the largest down with the
// half-way correction, as math.fsum).
Real exact_sum(const std::vector<Real>& xs) {
  std::vector<Real> partials;
  for (Real x : xs) {
    std::size_t i = 0;
    for (Real y : partials) {
      if (std::abs(x) < std::abs(y)) std::swap(x, y);
      const Real hi = x + y;
      const Real lo = y - (hi - x);
      if (lo != 0) partials[i++] = lo;
      x = hi;
    }
    partials.resize(i);
    partials.push_back(x);
  }
  if (partials.empty()) return 0;
  std::size_t n = partials.size();
  Real hi = partials[--n], lo = 0;
  while (n > 0) {
    const Real x = hi, y = partials[--n];
    hi = x + y;
    lo = y - (hi - x);
    if (lo != 0) break;
  }
  if (n > 0 && ((lo < 0 && partials[n - 1] < 0) || (lo > 0 && partials[n - 1] > 0))) {
    const Real y = lo * 2, x = hi + y;
    if (y == x - hi) hi = x;
  }
  return hi;
}

std::uint64_t bits(Real x) {
  return std::bit_cast<std::uint64_t>(x);
}

// Terms spread over 24 decades with both signs, and pairs that cancel: a sum whose plain
// floating-point value depends on the order.
std::vector<Real> hard_terms(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<Real> decade(-12.0, 12.0), unit(0.5, 1.0);
  std::vector<Real> xs;
  while (xs.size() < n) {
    const Real x = unit(rng) * std::pow(10.0, decade(rng)) * (rng() % 2 ? 1 : -1);
    xs.push_back(x);
    if (rng() % 4 == 0 && xs.size() < n) xs.push_back(-x * (1 + 1e-9));
  }
  return xs;
}

Real max_abs(const std::vector<Real>& xs) {
  Real m = 0;
  for (Real x : xs)
    m = std::max(m, std::abs(x));
  return m;
}

Real serial(const std::vector<Real>& xs) {
  ReproducibleSum s(max_abs(xs), static_cast<std::int64_t>(xs.size()));
  for (Real x : xs)
    s.add(x);
  return s.value();
}

TEST(ReproducibleSum, SameBitsInAnyOrderAndCloseToTheExactSum) {
  std::vector<Real> xs = hard_terms(100000, 7);
  const Real exact = exact_sum(xs);
  ReproducibleSum s(max_abs(xs), static_cast<std::int64_t>(xs.size()));
  for (Real x : xs)
    s.add(x);
  const Real first = s.value();
  // Within the dropped remainders' bound and one rounding of the result.
  const Real ulp =
      std::nextafter(std::abs(exact), std::numeric_limits<Real>::infinity()) - std::abs(exact);
  EXPECT_LE(std::abs(first - exact), s.error_bound() + 2 * ulp)
      << "sum " << first << " exact " << exact << " bound " << s.error_bound();
  // And as accurate as a double can be here: the three levels keep 105 bits below the bound
  // 2^e0 (one level alone is off by about 160 here, the sum being about -1e12).
  EXPECT_LE(std::abs(first - exact), 2 * ulp) << "sum " << first << " exact " << exact;
  std::mt19937_64 rng(11);
  bool naive_moved = false;
  Real naive_first = 0;
  for (Real x : xs)
    naive_first += x;
  for (int shuffle = 0; shuffle < 6; ++shuffle) {
    if (shuffle == 5)
      std::reverse(xs.begin(), xs.end());
    else
      std::shuffle(xs.begin(), xs.end(), rng);
    EXPECT_EQ(bits(serial(xs)), bits(first)) << "shuffle " << shuffle;
    Real naive = 0;
    for (Real x : xs)
      naive += x;
    naive_moved = naive_moved || bits(naive) != bits(naive_first);
  }
  // The check means something: the plain sum of these terms does move with the order.
  EXPECT_TRUE(naive_moved);
}

TEST(ReproducibleSum, SplitsMergedInAnyOrderGiveTheSameBits) {
  const std::vector<Real> xs = hard_terms(50000, 3);
  const Real m = max_abs(xs);
  const auto n = static_cast<std::int64_t>(xs.size());
  const Real whole = serial(xs);
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 5; ++trial) {
    // Cut into pieces of random sizes, summed apart, merged in a random order.
    std::vector<ReproducibleSum> pieces;
    std::size_t at = 0;
    while (at < xs.size()) {
      const std::size_t len = std::min<std::size_t>(xs.size() - at, 1 + rng() % 5000);
      ReproducibleSum p(m, n);
      for (std::size_t i = at; i < at + len; ++i)
        p.add(xs[i]);
      pieces.push_back(p);
      at += len;
    }
    std::shuffle(pieces.begin(), pieces.end(), rng);
    ReproducibleSum total(m, n);
    for (const auto& p : pieces)
      total.merge(p);
    EXPECT_EQ(bits(total.value()), bits(whole)) << "trial " << trial;
  }
}

TEST(ReproducibleSum, ParallelHelperIsTheSameOnOneAndTwoThreads) {
  const std::vector<Real> xs = hard_terms(200000, 9);
  const Real expected = serial(xs);
  const int threads = omp_get_max_threads();
  for (int t : {1, 2}) {
    omp_set_num_threads(t);
    const Real got = crater::parallel::reproducible_sum(
        static_cast<Index>(xs.size()), [&](Index i) { return xs[static_cast<std::size_t>(i)]; });
    EXPECT_EQ(bits(got), bits(expected)) << t << " threads";
  }
  omp_set_num_threads(threads);
}

// parallel::reproducible_sums (comm.hpp), without a communicator: each of its quantities is the
// ReproducibleSum of the admitted terms, made with their bound and count (the same bits as
// `serial` of them), on one and two threads and in any order of the indices; a quantity with
// no nonzero term is +0. Its sums over ranks: tests/mpi/test_dem_ranks.cpp (moving walls).
TEST(ReproducibleSum, SeveralQuantitiesOverAdmittedIndices) {
  constexpr std::size_t kQ = 3;
  const std::vector<Real> a = hard_terms(60000, 21), b = hard_terms(60000, 22);
  const auto n = static_cast<Index>(a.size());
  auto admitted = [](Index i) { return i % 3 != 1; };
  std::vector<Real> a_in, b_in;
  for (Index i = 0; i < n; ++i)
    if (admitted(i)) {
      a_in.push_back(a[static_cast<std::size_t>(i)]);
      b_in.push_back(b[static_cast<std::size_t>(i)]);
    }
  // serial() makes its sum with the bound and count of the terms it is given: the admitted ones.
  const Real want_a = serial(a_in), want_b = serial(b_in);
  std::vector<Index> order(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i)
    order[static_cast<std::size_t>(i)] = i;
  const int threads = omp_get_max_threads();
  std::mt19937_64 rng(4);
  for (int t : {1, 2}) {
    omp_set_num_threads(t);
    for (int trial = 0; trial < 2; ++trial) {
      const auto got = crater::parallel::reproducible_sums<kQ>(
          nullptr, n, [&](Index k) { return admitted(order[static_cast<std::size_t>(k)]); },
          [&](Index k) {
            const auto i = static_cast<std::size_t>(order[static_cast<std::size_t>(k)]);
            return std::array<Real, kQ>{a[i], b[i], 0.0};
          });
      EXPECT_EQ(bits(got[0]), bits(want_a)) << t << " threads, trial " << trial;
      EXPECT_EQ(bits(got[1]), bits(want_b)) << t << " threads, trial " << trial;
      EXPECT_EQ(bits(got[2]), bits(0.0));
      std::shuffle(order.begin(), order.end(), rng);
    }
  }
  omp_set_num_threads(threads);
}

TEST(ReproducibleSum, ZerosAndNonFiniteTerms) {
  ReproducibleSum zeros(0, 3);
  for (int i = 0; i < 3; ++i)
    zeros.add(0.0);
  EXPECT_EQ(bits(zeros.value()), bits(0.0));
  const Real inf = std::numeric_limits<Real>::infinity();
  ReproducibleSum with_inf(1.0, 3);
  with_inf.add(1.0);
  with_inf.add(inf);
  EXPECT_EQ(with_inf.value(), inf);
  with_inf.add(-inf);
  EXPECT_TRUE(std::isnan(with_inf.value()));
  ReproducibleSum with_nan(1.0, 2);
  with_nan.add(std::numeric_limits<Real>::quiet_NaN());
  with_nan.add(1.0);
  EXPECT_TRUE(std::isnan(with_nan.value()));
  // Small exact sums come out exactly.
  ReproducibleSum small(3.0, 3);
  for (Real x : {1.0, 2.0, 3.0})
    small.add(x);
  EXPECT_EQ(small.value(), 6.0);
}

}  // namespace
