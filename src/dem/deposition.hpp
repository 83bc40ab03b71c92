// What the disk and sphere depositions of dense_packing.hpp share (internal to src/dem): the
// radii window, the open grains lowest first, the cell grid, the test that a grain fits, and
// the loop that places grains. Derived (CRTP) supplies where a grain of radius r may rest:
// lowest_next_to(a, r), next to open grain a, and lowest_on_supports(r), on the faces and
// bodies alone.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <queue>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "dem/dense_packing.hpp"

namespace crater::dem::detail {

/// A support that is not a grain. Flat: a line (2D) or plane (3D) a grain's centre may lie on,
/// n . x = c + r, n towards where the grain may be; an obstacle's face only where the foot
/// falls on it (coordinates within [lo, hi] on the other axes). Else a point or ball a grain
/// may rest against (an obstacle's corner: radius 0; a disk or ball obstacle: its radius).
template <int D>
struct Support {
  bool flat = true;
  Vec<D> n = Vec<D>::Zero();
  Real c = 0;
  Vec<D> lo = Vec<D>::Constant(-std::numeric_limits<Real>::infinity());
  Vec<D> hi = Vec<D>::Constant(std::numeric_limits<Real>::infinity());
  Vec<D> centre = Vec<D>::Zero();
  Real radius = 0;

  /// Whether x lies within the face's extent (to eps).
  bool on_face(const Vec<D>& x, Real eps) const {
    for (int d = 0; d < D; ++d)
      if (x[d] < lo[d] - eps || x[d] > hi[d] + eps) return false;
    return true;
  }
};

/// The supports of a packing: the box's faces (from inside), then per body kept clear its
/// ball, or its faces (from outside) and corners.
template <int D>
std::vector<Support<D>> supports_of(const DensePackingInput<D>& in) {
  std::vector<Support<D>> out;
  for (int d = 0; d < D; ++d) {
    Support<D> lo, hi;
    lo.n[d] = 1;
    lo.c = in.lo[d];
    hi.n[d] = -1;
    hi.c = -in.hi[d];
    out.push_back(lo);
    out.push_back(hi);
  }
  for (const parts::RegionConfig& k : in.keep_clear) {
    if (k.type != parts::RegionType::Box) {
      Support<D> s;
      s.flat = false;
      s.centre = parts::to_vec<D>(k.center_m);
      s.radius = k.radius_m;
      out.push_back(s);
      continue;
    }
    const Vec<D> lo = parts::to_vec<D>(k.min_m), hi = parts::to_vec<D>(k.max_m);
    for (int d = 0; d < D; ++d)
      for (const Real sign : {Real(-1), Real(1)}) {
        Support<D> s;
        s.n[d] = sign;
        s.c = sign * (sign < 0 ? lo[d] : hi[d]);
        s.lo = lo;
        s.hi = hi;
        s.lo[d] = -std::numeric_limits<Real>::infinity();
        s.hi[d] = std::numeric_limits<Real>::infinity();
        out.push_back(s);
      }
    for (int m = 0; m < (1 << D); ++m) {
      Support<D> s;
      s.flat = false;
      for (int d = 0; d < D; ++d)
        s.centre[d] = (m >> d & 1) ? hi[d] : lo[d];
      out.push_back(s);
    }
  }
  return out;
}

template <int D, class Derived, int Window>
class Deposition {
 public:
  explicit Deposition(const DensePackingInput<D>& in)
      : in_(in), eps_(1e-9 * in.r_max), rng_(in.seed), draw_(in.r_min, in.r_max) {
    cell_ = 2 * in.r_max;
    std::int64_t total = 1;
    for (int d = 0; d < D; ++d) {
      cells_[d] = std::max<std::int64_t>(
          1, static_cast<std::int64_t>(std::ceil((in.hi[d] - in.lo[d]) / cell_)));
      total *= cells_[d];
    }
    head_.assign(static_cast<std::size_t>(total), -1);
  }

  std::vector<Grain<D>> run(DensePackingReport& report) {
    // The next Window radii of the draw, largest first: each place takes the largest of them
    // that fits (a pocket too small for one may hold another), so the grains are the draws,
    // each placed once, all but the last few.
    std::vector<Real> window;
    for (int k = 0; k < Window; ++k)
      window.push_back(draw());
    std::sort(window.begin(), window.end(), std::greater<>());
    auto take = [&](std::size_t k) {
      window.erase(window.begin() + static_cast<std::ptrdiff_t>(k));
      const Real r = draw();
      window.insert(std::lower_bound(window.begin(), window.end(), r, std::greater<>()), r);
    };
    const Derived& self = static_cast<const Derived&>(*this);
    bool placed_since_reopen = true;
    while (true) {
      if (open_.empty()) {
        if (auto [x, k] = first_fit(window, [&](Real r) { return self.lowest_on_supports(r); });
            x) {
          place(*x, window[k]);
          take(k);
          ++report.new_floors;
          placed_since_reopen = true;
          continue;
        }
        if (!placed_since_reopen || grains_.empty()) break;
        // Every grain open once more: a pocket a grain closed on may hold a grain drawn since.
        for (std::size_t i = 0; i < grains_.size(); ++i)
          open_.push({height(grains_[i].x), static_cast<std::int64_t>(i)});
        ++report.reopened;
        placed_since_reopen = false;
        continue;
      }
      const auto a = static_cast<std::size_t>(open_.top().second);
      if (auto [x, k] = first_fit(window, [&](Real r) { return self.lowest_next_to(a, r); }); x) {
        place(*x, window[k]);
        take(k);
        placed_since_reopen = true;
      } else {
        open_.pop();
      }
    }
    report.grains = grains_.size();
    return std::move(grains_);
  }

 protected:
  using V = Vec<D>;

  Real height(const V& x) const { return in_.up_sign * x[in_.up_axis]; }
  // Lower first; on equal heights, the smaller coordinates across, axis by axis.
  bool lower(const V& a, const V& b) const {
    const Real ha = height(a), hb = height(b);
    if (ha != hb) return ha < hb;
    for (int d = 0; d < D; ++d)
      if (d != in_.up_axis && a[d] != b[d]) return a[d] < b[d];
    return false;
  }

  // Whether a grain of radius r at x is wholly in the box and clear of the bodies.
  bool fits_box(const V& x, Real r) const {
    for (int d = 0; d < D; ++d)
      if (x[d] < in_.lo[d] + r - eps_ || x[d] > in_.hi[d] - r + eps_) return false;
    for (const parts::RegionConfig& k : in_.keep_clear)
      if (parts::region_distance<D>(k, x) < r - eps_) return false;
    return true;
  }

  // Whether grain j leaves room for a grain of radius r at x (touching allowed, to eps).
  bool clear_of(std::size_t j, const V& x, Real r) const {
    const Grain<D>& g = grains_[j];
    return !((x - g.x).squaredNorm() < (r + g.r - eps_) * (r + g.r - eps_));
  }

  // Whether a grain of radius r fits at x, a place touching an open grain: in the box, clear of
  // the bodies and of the grains `in_way` (all that can overlap such a place), the one that was
  // last in the way (index `last` into in_way, updated) tried first.
  bool fits_among(const std::vector<std::size_t>& in_way, std::size_t& last, const V& x,
                  Real r) const {
    if (!clear_of(in_way[last], x, r)) return false;
    for (std::size_t k = 0; k < in_way.size(); ++k)
      if (!clear_of(in_way[k], x, r)) {
        last = k;
        return false;
      }
    return fits_box(x, r);
  }

  // Whether a grain of radius r fits at x: wholly in the box, clear of the bodies and of every
  // grain.
  bool fits(const V& x, Real r) const {
    return fits_box(x, r) && !any_near(x, r + in_.r_max, [&](std::int64_t j) {
             return !clear_of(static_cast<std::size_t>(j), x, r);
           });
  }

  // Whether pred(j) holds for a grain j in the cells within `reach` of x (the first axis
  // fastest, as for_near; it stops at the first).
  template <class P>
  bool any_near(const V& x, Real reach, P&& pred) const {
    std::array<std::int64_t, D> lo, hi, c;
    if (!cells_near(x, reach, lo, hi)) return false;
    c = lo;
    while (true) {
      for (std::int64_t g = head_[cell_index(c)]; g >= 0; g = next_[static_cast<std::size_t>(g)])
        if (pred(g)) return true;
      int d = 0;
      while (d < D && ++c[d] > hi[d]) {
        c[d] = lo[d];
        ++d;
      }
      if (d == D) return false;
    }
  }

  // f(j) for every grain j in the cells within `reach` of x (the first axis fastest).
  template <class F>
  void for_near(const V& x, Real reach, F&& f) const {
    any_near(x, reach, [&](std::int64_t j) {
      f(j);
      return false;
    });
  }

  // The cells within `reach` of x, each axis's range (clamped to the grid as any_near's); false
  // when none.
  bool cells_near(const V& x, Real reach, std::array<std::int64_t, D>& lo,
                  std::array<std::int64_t, D>& hi) const {
    for (int d = 0; d < D; ++d) {
      lo[d] = std::max<std::int64_t>(
          0, static_cast<std::int64_t>(std::floor((x[d] - reach - in_.lo[d]) / cell_)));
      hi[d] = std::min<std::int64_t>(
          cells_[d] - 1, static_cast<std::int64_t>(std::floor((x[d] + reach - in_.lo[d]) / cell_)));
      if (hi[d] < lo[d]) return false;
    }
    return true;
  }

  // The cell a grain at x is kept in.
  std::array<std::int64_t, D> cell_of(const V& x) const {
    std::array<std::int64_t, D> c;
    for (int d = 0; d < D; ++d)
      c[d] = std::clamp<std::int64_t>(
          static_cast<std::int64_t>(std::floor((x[d] - in_.lo[d]) / cell_)), 0, cells_[d] - 1);
    return c;
  }

  // The fitting points of pts[0..n), the lowest kept in best; fit(x) says whether x fits.
  template <class Points, class Fit>
  void consider(const Points& pts, int n, std::optional<V>& best, Fit&& fit) const {
    for (int q = 0; q < n; ++q)
      if ((!best || lower(pts[q], *best)) && fit(pts[q])) best = pts[q];
  }
  template <class Points>
  void consider(const Points& pts, int n, Real r, std::optional<V>& best) const {
    consider(pts, n, best, [&](const V& x) { return fits(x, r); });
  }

  const DensePackingInput<D>& in_;
  Real eps_;
  std::vector<Grain<D>> grains_;

 private:
  // The first radius of `window` (largest first) for which `where` finds a place, with its
  // index; no place when none fits.
  template <class Where>
  std::pair<std::optional<V>, std::size_t> first_fit(const std::vector<Real>& window,
                                                     Where&& where) const {
    for (std::size_t k = 0; k < window.size(); ++k) {
      // Equal radii fit alike: try each value once.
      if (k > 0 && window[k] == window[k - 1]) continue;
      if (auto x = where(window[k])) return {x, k};
    }
    return {std::nullopt, 0};
  }

  Real draw() { return in_.r_min == in_.r_max ? in_.r_min : draw_(rng_); }

  std::size_t cell_index(const std::array<std::int64_t, D>& c) const {
    std::int64_t i = 0;
    for (int d = D - 1; d >= 0; --d)
      i = i * cells_[d] + c[d];
    return static_cast<std::size_t>(i);
  }

  void place(const V& x, Real r) {
    if (grains_.size() >= in_.max_grains) throw std::length_error("dense packing: too many grains");
    const auto k = static_cast<std::int64_t>(grains_.size());
    grains_.push_back({x, r});
    const std::size_t cell = cell_index(cell_of(x));
    next_.push_back(head_[cell]);
    head_[cell] = k;
    open_.push({height(x), k});
  }

  std::mt19937_64 rng_;
  std::uniform_real_distribution<Real> draw_;
  Real cell_ = 0;
  std::array<std::int64_t, D> cells_{};
  std::vector<std::int64_t> head_, next_;  // per cell its last grain, per grain the one before
  // The open grains, lowest first (ties: the one placed first).
  using Open = std::pair<Real, std::int64_t>;
  std::priority_queue<Open, std::vector<Open>, std::greater<Open>> open_;
};

}  // namespace crater::dem::detail
