// Geometric deposition of disks; see dense_packing.hpp.
#include "dem/dense_packing.hpp"

#include "dem/deposition.hpp"

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

// circle_circle(p, a, q, b) with q - p given by its length d > 0 and direction u (computed
// as there): the same points, bit for bit.
int circle_circle_at(const V2& p, Real a, Real b, Real d, const V2& u, std::array<V2, 2>& out) {
  if (!(d > 0) || d > a + b || d < std::abs(a - b)) return 0;
  const Real x = (d * d + a * a - b * b) / (2 * d);
  const Real h = std::sqrt(std::max(Real(0), a * a - x * x));
  const V2 perp(-u[1], u[0]);
  out[0] = p + x * u + h * perp;
  out[1] = p + x * u - h * perp;
  return 2;
}

using Support = detail::Support<2>;

class Disks final : public detail::Deposition<2, Disks, 16> {
 public:
  explicit Disks(const DensePackingInput<2>& in)
      : Deposition(in), supports_(detail::supports_of(in)) {}

 private:
  friend class detail::Deposition<2, Disks, 16>;  // calls the two lowest_* below

  // Where a grain of radius r may stand touching the support (a circle of radius ra about pa
  // crossed with the support's locus at distance r).
  int cross_support(const Support& s, const V2& pa, Real ra, Real r, std::array<V2, 2>& out) const {
    if (!s.flat) return circle_circle(pa, ra, s.centre, s.radius + r, out);
    const int n = circle_line(pa, ra, s.n, s.c + r, out);
    // An edge of an obstacle holds the grain only where the grain's foot falls on it.
    int kept = 0;
    for (int q = 0; q < n; ++q)
      if (s.on_face(out[q], eps_)) out[kept++] = out[q];
    return kept;
  }

  // The lowest place next to open grain a where a grain of radius r rests on a and one more
  // support (a grain nearby, a face, an obstacle).
  std::optional<V2> lowest_next_to(std::size_t a, Real r) const {
    const Grain<2>& ga = grains_[a];
    const Real ra = ga.r + r;
    // The grains within reach, and of them those that can be in the way of a place touching a
    // (one in the way of x, |x - ga.x| = ga.r + r, is within ga.r + g.r + 2 r of a): the test
    // that a place is free looks at these (and a) alone, the one last in the way first. Both
    // in for_near's order, from the grains near a (near(a, r)).
    const std::vector<Near>& near = near_of(a, r);
    std::array<std::int64_t, 2> lo, hi;
    reach_.clear();
    in_way_.assign(1, a);
    if (cells_near(ga.x, ga.r + 2 * r + in_.r_max, lo, hi))
      for (const Near& n : near) {
        if (n.cell[0] < lo[0] || n.cell[0] > hi[0] || n.cell[1] < lo[1] || n.cell[1] > hi[1])
          continue;
        reach_.push_back(&n);
        if (n.d <= ga.r + grains_[n.j].r + 2 * r) in_way_.push_back(n.j);
      }
    std::size_t last_in_way = 0;
    auto free_at = [&](const V2& x) { return fits_among(in_way_, last_in_way, x, r); };
    std::optional<V2> best;
    std::array<V2, 2> pts;
    for (const Near* n : reach_)
      consider(pts, circle_circle_at(ga.x, ra, grains_[n->j].r + r, n->d, n->u, pts), best,
               free_at);
    for (const Support& s : supports_)
      consider(pts, cross_support(s, ga.x, ra, r, pts), best, free_at);
    return best;
  }

  // A grain near open grain a: its index, cell, distance from a and direction from a.
  struct Near {
    std::size_t j = 0;
    std::array<std::int64_t, 2> cell{};
    Real d = 0;
    V2 u = V2::Zero();
  };

  // The grains in the cells within a's reach for a grain of radius r or more, in for_near's
  // order (the first axis fastest): collected once per open grain and count of grains for the
  // largest radius asked (the window's radii come largest first), and filtered by cell for the
  // smaller ones, which keeps for_near's order.
  const std::vector<Near>& near_of(std::size_t a, Real r) const {
    if (near_a_ == a && near_count_ == grains_.size() && near_r_ >= r) return near_;
    near_a_ = a;
    near_count_ = grains_.size();
    near_r_ = r;
    near_.clear();
    const Grain<2>& ga = grains_[a];
    for_near(ga.x, ga.r + 2 * r + in_.r_max, [&](std::int64_t j) {
      if (static_cast<std::size_t>(j) == a) return;
      const Grain<2>& gb = grains_[static_cast<std::size_t>(j)];
      Near n;
      n.j = static_cast<std::size_t>(j);
      n.cell = cell_of(gb.x);
      const V2 pq = gb.x - ga.x;
      n.d = pq.norm();
      if (n.d > 0) n.u = pq / n.d;
      near_.push_back(n);
    });
    return near_;
  }

  // The lowest place that rests on two of the supports alone (a first grain, or the first on
  // an obstacle's top).
  std::optional<V2> lowest_on_supports(Real r) const {
    std::optional<V2> best;
    std::array<V2, 2> pts;
    for (std::size_t i = 0; i < supports_.size(); ++i)
      for (std::size_t j = i + 1; j < supports_.size(); ++j) {
        const Support &s = supports_[i], &t = supports_[j];
        if (s.flat && t.flat) {
          // Two lines offset by r: their crossing, when not parallel.
          const Real det = s.n[0] * t.n[1] - s.n[1] * t.n[0];
          if (std::abs(det) < 1e-12) continue;
          const Real cs = s.c + r, ct = t.c + r;
          pts[0] = V2((cs * t.n[1] - ct * s.n[1]) / det, (s.n[0] * ct - t.n[0] * cs) / det);
          consider(pts, s.on_face(pts[0], eps_) && t.on_face(pts[0], eps_) ? 1 : 0, r, best);
        } else if (!s.flat) {
          consider(pts, cross_support(t, s.centre, s.radius + r, r, pts), r, best);
        } else {
          consider(pts, cross_support(s, t.centre, t.radius + r, r, pts), r, best);
        }
      }
    return best;
  }

  const std::vector<Support> supports_;
  // Scratch of lowest_next_to (kept between calls: no allocation per call).
  mutable std::vector<Near> near_;
  mutable std::size_t near_a_ = static_cast<std::size_t>(-1), near_count_ = 0;
  mutable Real near_r_ = 0;
  mutable std::vector<const Near*> reach_;
  mutable std::vector<std::size_t> in_way_;
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
    grains = Disks(in).run(rep);
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
