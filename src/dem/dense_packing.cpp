// Geometric deposition of disks; see dense_packing.hpp.
#include "dem/dense_packing.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <queue>
#include <random>
#include <stdexcept>
#include <utility>

namespace crater::dem {
namespace {

using V2 = Vec<2>;

// Points at distance a from p and b from q (the two circles' crossings); none when they miss.
int circle_circle(const V2& p, Real a, const V2& q, Real b, std::array<V2, 2>& out) {
  const V2 pq = q - p;
  const Real d = pq.norm();
  if (!(d > 0) || d > a + b || d < std::abs(a - b)) return 0;
  const Real x = (d * d + a * a - b * b) / (2 * d);
  const Real h = std::sqrt(std::max(Real(0), a * a - x * x));
  const V2 u = pq / d;
  const V2 perp(-u[1], u[0]);
  out[0] = p + x * u + h * perp;
  out[1] = p + x * u - h * perp;
  return 2;
}

// Points at distance a from p on the line {x : x . n = c} (n a unit vector).
int circle_line(const V2& p, Real a, const V2& n, Real c, std::array<V2, 2>& out) {
  const Real delta = p.dot(n) - c;
  if (std::abs(delta) > a) return 0;
  const V2 foot = p - delta * n;
  const Real t = std::sqrt(std::max(Real(0), a * a - delta * delta));
  const V2 u(-n[1], n[0]);
  out[0] = foot + t * u;
  out[1] = foot - t * u;
  return 2;
}

// A support that is not a grain: a line a grain's centre may rest on (x . n = c + r, n
// pointing to where the grain may be; for an obstacle's edge, only where the foot falls on
// the edge: t in [t0, t1] along (-n_y, n_x)), or a point it may rest against (an obstacle's
// corner: radius 0; a disk obstacle: its radius).
struct Support {
  bool line = true;
  V2 n = V2::Zero();
  Real c = 0;
  Real t0 = -std::numeric_limits<Real>::infinity(), t1 = std::numeric_limits<Real>::infinity();
  V2 centre = V2::Zero();
  Real radius = 0;
};

class Deposition {
 public:
  explicit Deposition(const DensePackingInput<2>& in)
      : in_(in), rng_(in.seed), draw_(in.r_min, in.r_max), eps_(1e-9 * in.r_max) {
    cell_ = 2 * in.r_max;
    for (int d = 0; d < 2; ++d)
      cells_[d] = std::max<std::int64_t>(
          1, static_cast<std::int64_t>(std::ceil((in.hi[d] - in.lo[d]) / cell_)));
    head_.assign(static_cast<std::size_t>(cells_[0] * cells_[1]), -1);
    add_supports();
  }

  std::vector<Grain<2>> run(DensePackingReport& report) {
    // The next kWindow radii of the draw, largest first: each place takes the largest of them
    // that fits (a pocket too small for one may hold another), so the grains are the draws,
    // each placed once, all but the last few.
    std::vector<Real> window;
    for (int k = 0; k < kWindow; ++k)
      window.push_back(draw());
    std::sort(window.begin(), window.end(), std::greater<>());
    auto take = [&](std::size_t k) {
      window.erase(window.begin() + static_cast<std::ptrdiff_t>(k));
      const Real r = draw();
      window.insert(std::lower_bound(window.begin(), window.end(), r, std::greater<>()), r);
    };
    bool placed_since_reopen = true;
    while (true) {
      if (open_.empty()) {
        if (auto [x, k] = first_fit(window, [&](Real r) { return lowest_on_supports(r); }); x) {
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
      if (auto [x, k] = first_fit(window, [&](Real r) { return lowest_next_to(a, r); }); x) {
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

 private:
  static constexpr int kWindow = 16;

  // The first radius of `window` (largest first) for which `where` finds a place, with its
  // index; no place when none fits.
  template <class Where>
  std::pair<std::optional<V2>, std::size_t> first_fit(const std::vector<Real>& window,
                                                      Where&& where) const {
    for (std::size_t k = 0; k < window.size(); ++k) {
      // Equal radii fit alike: try each value once.
      if (k > 0 && window[k] == window[k - 1]) continue;
      if (auto x = where(window[k])) return {x, k};
    }
    return {std::nullopt, 0};
  }

  Real draw() { return in_.r_min == in_.r_max ? in_.r_min : draw_(rng_); }
  Real height(const V2& x) const { return in_.up_sign * x[in_.up_axis]; }
  // Lower first; on equal heights, the smaller coordinate across (then the smaller index).
  bool lower(const V2& a, const V2& b) const {
    const Real ha = height(a), hb = height(b);
    if (ha != hb) return ha < hb;
    return a[1 - in_.up_axis] < b[1 - in_.up_axis];
  }

  void add_supports() {
    // The box's faces, from inside.
    for (int d = 0; d < 2; ++d) {
      Support lo, hi;
      lo.n[d] = 1;
      lo.c = in_.lo[d];
      hi.n[d] = -1;
      hi.c = -in_.hi[d];
      supports_.push_back(lo);
      supports_.push_back(hi);
    }
    for (const parts::RegionConfig& k : in_.keep_clear) {
      if (k.type != parts::RegionType::Box) {
        Support s;
        s.line = false;
        s.centre = parts::to_vec<2>(k.center_m);
        s.radius = k.radius_m;
        supports_.push_back(s);
        continue;
      }
      const V2 lo = parts::to_vec<2>(k.min_m), hi = parts::to_vec<2>(k.max_m);
      for (int d = 0; d < 2; ++d) {
        const int e = 1 - d;
        // Along (-n_y, n_x): for n = +-e_d that is -+ e_e... measured as t = x . (-n_y, n_x).
        for (const Real sign : {Real(-1), Real(1)}) {
          Support s;
          s.n[d] = sign;
          s.c = sign * (sign < 0 ? lo[d] : hi[d]);
          const V2 u(-s.n[1], s.n[0]);
          const Real a = u[e] * lo[e], b = u[e] * hi[e];
          s.t0 = std::min(a, b);
          s.t1 = std::max(a, b);
          supports_.push_back(s);
        }
      }
      for (const V2& corner : {lo, hi, V2(lo[0], hi[1]), V2(hi[0], lo[1])}) {
        Support s;
        s.line = false;
        s.centre = corner;
        supports_.push_back(s);
      }
    }
  }

  // Where a grain of radius r may stand touching the support (a circle of radius ra about pa
  // crossed with the support's locus at distance r).
  int cross_support(const Support& s, const V2& pa, Real ra, Real r, std::array<V2, 2>& out) const {
    if (!s.line) return circle_circle(pa, ra, s.centre, s.radius + r, out);
    int n = circle_line(pa, ra, s.n, s.c + r, out);
    // An edge of an obstacle holds the grain only where the grain's foot falls on it.
    const V2 u(-s.n[1], s.n[0]);
    int kept = 0;
    for (int q = 0; q < n; ++q) {
      const Real t = out[q].dot(u);
      if (t >= s.t0 - eps_ && t <= s.t1 + eps_) out[kept++] = out[q];
    }
    n = kept;
    return n;
  }

  // Whether a grain of radius r fits at x: wholly in the box, clear of the obstacles and of
  // every grain (touching allowed, to eps).
  bool fits(const V2& x, Real r) const {
    for (int d = 0; d < 2; ++d)
      if (x[d] < in_.lo[d] + r - eps_ || x[d] > in_.hi[d] - r + eps_) return false;
    for (const parts::RegionConfig& k : in_.keep_clear)
      if (parts::region_distance<2>(k, x) < r - eps_) return false;
    bool clear = true;
    for_near(x, r + in_.r_max, [&](std::int64_t j) {
      const Grain<2>& g = grains_[static_cast<std::size_t>(j)];
      if ((x - g.x).squaredNorm() < (r + g.r - eps_) * (r + g.r - eps_)) clear = false;
    });
    return clear;
  }

  template <class F>
  void for_near(const V2& x, Real reach, F&& f) const {
    std::array<std::int64_t, 2> lo, hi;
    for (int d = 0; d < 2; ++d) {
      lo[d] = std::max<std::int64_t>(
          0, static_cast<std::int64_t>(std::floor((x[d] - reach - in_.lo[d]) / cell_)));
      hi[d] = std::min<std::int64_t>(
          cells_[d] - 1, static_cast<std::int64_t>(std::floor((x[d] + reach - in_.lo[d]) / cell_)));
    }
    for (std::int64_t j = lo[1]; j <= hi[1]; ++j)
      for (std::int64_t i = lo[0]; i <= hi[0]; ++i)
        for (std::int64_t g = head_[static_cast<std::size_t>(j * cells_[0] + i)]; g >= 0;
             g = next_[static_cast<std::size_t>(g)])
          f(g);
  }

  void consider(const std::array<V2, 2>& pts, int n, Real r, std::optional<V2>& best) const {
    for (int q = 0; q < n; ++q)
      if ((!best || lower(pts[q], *best)) && fits(pts[q], r)) best = pts[q];
  }

  // The lowest place next to open grain a where a grain of radius r rests on a and one more
  // support (a grain nearby, a face, an obstacle).
  std::optional<V2> lowest_next_to(std::size_t a, Real r) const {
    const Grain<2>& ga = grains_[a];
    const Real ra = ga.r + r;
    std::optional<V2> best;
    std::array<V2, 2> pts;
    for_near(ga.x, ga.r + 2 * r + in_.r_max, [&](std::int64_t j) {
      if (static_cast<std::size_t>(j) == a) return;
      const Grain<2>& gb = grains_[static_cast<std::size_t>(j)];
      consider(pts, circle_circle(ga.x, ra, gb.x, gb.r + r, pts), r, best);
    });
    for (const Support& s : supports_)
      consider(pts, cross_support(s, ga.x, ra, r, pts), r, best);
    return best;
  }

  // The lowest place that rests on two of the supports alone (a first grain, or the first on
  // an obstacle's top).
  std::optional<V2> lowest_on_supports(Real r) const {
    std::optional<V2> best;
    std::array<V2, 2> pts;
    for (std::size_t i = 0; i < supports_.size(); ++i)
      for (std::size_t j = i + 1; j < supports_.size(); ++j) {
        const Support &s = supports_[i], &t = supports_[j];
        if (s.line && t.line) {
          // Two lines offset by r: their crossing, when not parallel.
          const Real det = s.n[0] * t.n[1] - s.n[1] * t.n[0];
          if (std::abs(det) < 1e-12) continue;
          const Real cs = s.c + r, ct = t.c + r;
          pts[0] = V2((cs * t.n[1] - ct * s.n[1]) / det, (s.n[0] * ct - t.n[0] * cs) / det);
          consider(pts, on_edges(s, t, pts[0]) ? 1 : 0, r, best);
        } else if (!s.line) {
          consider(pts, cross_support(t, s.centre, s.radius + r, r, pts), r, best);
        } else {
          consider(pts, cross_support(s, t.centre, t.radius + r, r, pts), r, best);
        }
      }
    return best;
  }

  bool on_edges(const Support& s, const Support& t, const V2& x) const {
    for (const Support* e : {&s, &t}) {
      const Real u = x.dot(V2(-e->n[1], e->n[0]));
      if (u < e->t0 - eps_ || u > e->t1 + eps_) return false;
    }
    return true;
  }

  void place(const V2& x, Real r) {
    if (grains_.size() >= in_.max_grains) throw std::length_error("dense packing: too many grains");
    const auto k = static_cast<std::int64_t>(grains_.size());
    grains_.push_back({x, r});
    std::array<std::int64_t, 2> c;
    for (int d = 0; d < 2; ++d)
      c[d] = std::clamp<std::int64_t>(
          static_cast<std::int64_t>(std::floor((x[d] - in_.lo[d]) / cell_)), 0, cells_[d] - 1);
    const auto cell = static_cast<std::size_t>(c[1] * cells_[0] + c[0]);
    next_.push_back(head_[cell]);
    head_[cell] = k;
    open_.push({height(x), k});
  }

  const DensePackingInput<2>& in_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<Real> draw_;
  Real eps_;
  Real cell_ = 0;
  std::array<std::int64_t, 2> cells_{};
  std::vector<std::int64_t> head_, next_;  // per cell its last grain, per grain the one before
  std::vector<Grain<2>> grains_;
  std::vector<Support> supports_;
  // The open grains, lowest first (ties: the one placed first).
  using Open = std::pair<Real, std::int64_t>;
  std::priority_queue<Open, std::vector<Open>, std::greater<Open>> open_;
};

}  // namespace

template <int D>
std::vector<Grain<D>> dense_packing(const DensePackingInput<D>& in, DensePackingReport* report) {
  if (!(in.r_min > 0) || !(in.r_max >= in.r_min))
    throw std::invalid_argument("dense packing: radii must satisfy 0 < r_min <= r_max");
  for (int d = 0; d < D; ++d)
    if (!(in.hi[d] - in.lo[d] >= 2 * in.r_max))
      throw std::invalid_argument("dense packing: the box is thinner than a grain");
  if (in.up_axis < 0 || in.up_axis >= D)
    throw std::invalid_argument("dense packing: up_axis must name an axis");
  DensePackingReport local;
  DensePackingReport& rep = report ? *report : local;
  rep = DensePackingReport{};
  std::vector<Grain<D>> grains;
  if constexpr (D == 2)
    grains = Deposition(in).run(rep);
  else
    grains = detail::deposit_spheres(in, rep);
  for (const Grain<D>& g : grains)
    rep.solid_volume += grain_volume<D>(g.r);
  parts::RegionConfig box;
  for (int d = 0; d < D; ++d) {
    box.min_m[static_cast<std::size_t>(d)] = in.lo[d];
    box.max_m[static_cast<std::size_t>(d)] = in.hi[d];
  }
  rep.free_volume = parts::region_volume_of<D>(box) - parts::carved_volume<D>(box, in.keep_clear);
  return grains;
}

template std::vector<Grain<2>> dense_packing<2>(const DensePackingInput<2>&, DensePackingReport*);
template std::vector<Grain<3>> dense_packing<3>(const DensePackingInput<3>&, DensePackingReport*);

}  // namespace crater::dem
