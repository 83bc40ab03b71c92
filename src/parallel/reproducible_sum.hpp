// Sums whose bits do not depend on the order of their terms, nor on how the terms are split
// among threads or ranks (issue 29, docs/distributed.md): pre-rounding to fixed levels, after
// J. Demmel and H. D. Nguyen, "Parallel reproducible summation", IEEE Transactions on Computers
// 64(7), 2015.
//
// Given bounds M >= |x| and n >= the number of terms, level 0 takes each term rounded to the grid
// of 2^(e0 - 52), e0 = ceil(log2 M) + ceil(log2 n) + 1: q = (s + x) - s with s = 1.5 * 2^e0 (the
// 1.5 keeps s + x in one binade, so q is a multiple of that grid; the rounding is x's alone).
// Every partial sum of such q is a multiple of the grid below 2^(e0 + 1), so it is exact: the
// level's sum has the same bits in any order. The remainder x - q (exact) goes to level 1, W =
// 52 - ceil(log2 n) bits further down, and so on over kLevels levels; what is left below the
// last level is dropped (at most n * 2^(e_last - 53): error_bound()). value() adds the levels,
// smallest first. Non-finite terms are summed apart (their sum, NaN or +-inf, does not depend
// on the order either) and returned instead.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/types.hpp"
#include "parallel/parallel.hpp"

namespace crater::parallel {

class ReproducibleSum {
 public:
  static constexpr int kLevels = 3;

  /// A sum with no finite level: of zeros alone (made with bound 0).
  ReproducibleSum() = default;

  /// An empty sum of at most `count` terms, each finite term at most `max_abs` in magnitude.
  ReproducibleSum(Real max_abs, std::int64_t count) {
    const int log_n =
        count > 1 ? static_cast<int>(std::ceil(std::log2(static_cast<Real>(count)))) : 0;
    if (!(max_abs > 0) || !std::isfinite(max_abs)) {
      levels_ = 0;  // nothing finite but zeros: the sum is +0
      return;
    }
    int e = std::ilogb(max_abs) + 1 + log_n + 1;  // 2^ilogb <= M < 2^(ilogb + 1)
    const int step = 52 - log_n;
    for (levels_ = 0; levels_ < kLevels; ++levels_) {
      if (e > std::numeric_limits<Real>::max_exponent - 2 || e - 52 < kLowestExponent) break;
      shift_[static_cast<std::size_t>(levels_)] = std::ldexp(Real(1.5), e);
      last_exponent_ = e;
      e -= step;
    }
    count_ = count;
  }

  void add(Real x) {
    if (!std::isfinite(x)) {
      nonfinite_ += x;
      return;
    }
    for (int k = 0; k < levels_; ++k) {
      const auto u = static_cast<std::size_t>(k);
      const Real q = (shift_[u] + x) - shift_[u];
      sum_[u] += q;
      x -= q;
    }
  }

  /// Adds another sum made with the same bounds (exact: any merge order gives the same bits).
  void merge(const ReproducibleSum& other) {
    for (std::size_t k = 0; k < kLevels; ++k)
      sum_[k] += other.sum_[k];
    nonfinite_ += other.nonfinite_;
  }

  /// The levels' sums and the non-finite terms' sum: what ranks add up to merge their sums
  /// (each entry is exact, so any order of those additions gives the same bits).
  using Partials = std::array<Real, kLevels + 1>;
  Partials partials() const {
    Partials p{};
    for (std::size_t k = 0; k < kLevels; ++k)
      p[k] = sum_[k];
    p[kLevels] = nonfinite_;
    return p;
  }
  void set_partials(const Partials& p) {
    for (std::size_t k = 0; k < kLevels; ++k)
      sum_[k] = p[k];
    nonfinite_ = p[kLevels];
  }

  Real value() const {
    if (nonfinite_ != 0 || std::isnan(nonfinite_)) return nonfinite_;
    Real s = 0;
    for (int k = levels_ - 1; k >= 0; --k)
      s += sum_[static_cast<std::size_t>(k)];
    return s;
  }

  /// The most the dropped remainders can add up to (value()'s own rounding aside).
  Real error_bound() const {
    return levels_ == 0 ? 0 : static_cast<Real>(count_) * std::ldexp(Real(1), last_exponent_ - 53);
  }

 private:
  static constexpr int kLowestExponent = std::numeric_limits<Real>::min_exponent - 1;
  std::array<Real, kLevels> shift_{};
  std::array<Real, kLevels> sum_{};
  Real nonfinite_ = 0;
  int levels_ = 0;
  int last_exponent_ = 0;
  std::int64_t count_ = 0;
};

/// Sum of f(i) over [0, n) with the same bits for any order, thread count or split (f is
/// evaluated twice: once for the bound max |f(i)|, once to add).
template <class F>
Real reproducible_sum(Index n, F&& f) {
  const Real bound = max_over(n, Real(0), [&](Index i) {
    const Real x = f(i);
    return std::isfinite(x) ? std::abs(x) : Real(0);
  });
  ReproducibleSum total(bound, n);
#pragma omp parallel if (n >= parallel_min())
  {
    ReproducibleSum local(bound, n);
#pragma omp for schedule(static) nowait
    for (Index i = 0; i < n; ++i)
      local.add(f(i));
#pragma omp critical(crater_reproducible_sum)
    total.merge(local);
  }
  return total.value();
}

}  // namespace crater::parallel
