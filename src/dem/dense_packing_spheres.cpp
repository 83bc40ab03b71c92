// Geometric deposition of spheres (3D); see dense_packing.hpp. As for disks, each grain goes to
// the lowest place next to the lowest open grain where it rests on that grain and two more
// supports (grains, the box's faces, the bodies kept clear: balls, and boxes by their faces
// and corners; a grain resting on a box's edge alone is not looked for).
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <queue>
#include <random>
#include <stdexcept>
#include <utility>

#include <Eigen/Geometry>

#include "dem/dense_packing.hpp"

namespace crater::dem::detail {
namespace {

using V3 = Vec<3>;
using Points = std::array<V3, 2>;

// Where a centre at distance a from p, b from q and c from s can be (three spheres' crossings).
int sphere_sphere_sphere(const V3& p, Real a, const V3& q, Real b, const V3& s, Real c,
                         Points& out) {
  V3 ex = q - p;
  const Real d = ex.norm();
  if (!(d > 0)) return 0;
  ex /= d;
  const V3 ps = s - p;
  const Real i = ex.dot(ps);
  V3 ey = ps - i * ex;
  const Real j = ey.norm();
  if (!(j > 1e-12 * d)) return 0;
  ey /= j;
  const V3 ez = ex.cross(ey);
  const Real x = (a * a - b * b + d * d) / (2 * d);
  const Real y = (a * a - c * c + i * i + j * j) / (2 * j) - i / j * x;
  const Real z2 = a * a - x * x - y * y;
  if (z2 < 0) return 0;
  const Real z = std::sqrt(z2);
  out[0] = p + x * ex + y * ey + z * ez;
  out[1] = p + x * ex + y * ey - z * ez;
  return 2;
}

// At distance a from p and b from q, on the plane n . x = c (n a unit vector).
int sphere_sphere_plane(const V3& p, Real a, const V3& q, Real b, const V3& n, Real c,
                        Points& out) {
  V3 u = q - p;
  const Real d = u.norm();
  if (!(d > 0)) return 0;
  u /= d;
  const Real along = (d * d + a * a - b * b) / (2 * d);
  const Real h2 = a * a - along * along;
  if (h2 < 0) return 0;
  const Real h = std::sqrt(h2);
  const V3 centre = p + along * u;
  int k = 0;
  for (int m = 1; m < 3; ++m)
    if (std::abs(u[m]) < std::abs(u[k])) k = m;
  const V3 e1 = u.cross(V3::Unit(k)).normalized();
  const V3 e2 = u.cross(e1);
  const Real A = h * n.dot(e1), B = h * n.dot(e2), K = c - n.dot(centre);
  const Real rho = std::hypot(A, B);
  if (!(rho > 1e-15 * (h + 1)) || std::abs(K) > rho) return 0;
  const Real phi = std::atan2(B, A), t = std::acos(std::clamp(K / rho, Real(-1), Real(1)));
  out[0] = centre + h * (std::cos(phi + t) * e1 + std::sin(phi + t) * e2);
  out[1] = centre + h * (std::cos(phi - t) * e1 + std::sin(phi - t) * e2);
  return 2;
}

// At distance a from p, on the planes n1 . x = c1 and n2 . x = c2.
int sphere_plane_plane(const V3& p, Real a, const V3& n1, Real c1, const V3& n2, Real c2,
                       Points& out) {
  const V3 t = n1.cross(n2);
  const Real tt = t.squaredNorm();
  if (!(tt > 1e-20)) return 0;
  const V3 x0 = (c1 * n2.cross(t) + c2 * t.cross(n1)) / tt;
  const V3 dir = t / std::sqrt(tt);
  const V3 w = x0 - p;
  const Real half_b = dir.dot(w), disc = half_b * half_b - (w.squaredNorm() - a * a);
  if (disc < 0) return 0;
  const Real root = std::sqrt(disc);
  out[0] = x0 + (-half_b + root) * dir;
  out[1] = x0 + (-half_b - root) * dir;
  return 2;
}

// A support that is not a grain: a plane a centre may lie on (n . x = c + r, n towards where
// the grain may be; an obstacle's face only where the foot falls on it, inside [lo, hi] on
// the other axes), or a point or ball a grain may rest against (a corner: radius 0).
struct Support {
  bool plane = true;
  V3 n = V3::Zero();
  Real c = 0;
  V3 lo = V3::Constant(-std::numeric_limits<Real>::infinity());
  V3 hi = V3::Constant(std::numeric_limits<Real>::infinity());
  V3 centre = V3::Zero();
  Real radius = 0;
};

// A locus of centres for a grain of radius r: a sphere (centre, radius) or a plane.
struct Locus {
  bool plane = false;
  V3 p = V3::Zero();              // sphere centre
  Real R = 0;                     // sphere radius
  V3 n = V3::Zero();              // plane normal
  Real c = 0;                     // plane offset
  const Support* face = nullptr;  // the plane's support (for its extent)
};

class Deposition3 {
 public:
  explicit Deposition3(const DensePackingInput<3>& in)
      : in_(in), rng_(in.seed), draw_(in.r_min, in.r_max), eps_(1e-9 * in.r_max) {
    cell_ = 2 * in.r_max;
    for (int d = 0; d < 3; ++d)
      cells_[d] = std::max<std::int64_t>(
          1, static_cast<std::int64_t>(std::ceil((in.hi[d] - in.lo[d]) / cell_)));
    head_.assign(static_cast<std::size_t>(cells_[0] * cells_[1] * cells_[2]), -1);
    add_supports();
  }

  std::vector<Grain<3>> run(DensePackingReport& report) {
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
  static constexpr int kWindow = 8;

  template <class Where>
  std::pair<std::optional<V3>, std::size_t> first_fit(const std::vector<Real>& window,
                                                      Where&& where) const {
    for (std::size_t k = 0; k < window.size(); ++k) {
      if (k > 0 && window[k] == window[k - 1]) continue;
      if (auto x = where(window[k])) return {x, k};
    }
    return {std::nullopt, 0};
  }

  Real draw() { return in_.r_min == in_.r_max ? in_.r_min : draw_(rng_); }
  Real height(const V3& x) const { return in_.up_sign * x[in_.up_axis]; }
  bool lower(const V3& a, const V3& b) const {
    const Real ha = height(a), hb = height(b);
    if (ha != hb) return ha < hb;
    for (int d = 0; d < 3; ++d)
      if (d != in_.up_axis && a[d] != b[d]) return a[d] < b[d];
    return false;
  }

  void add_supports() {
    for (int d = 0; d < 3; ++d) {
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
        s.plane = false;
        s.centre = parts::to_vec<3>(k.center_m);
        s.radius = k.radius_m;
        supports_.push_back(s);
        continue;
      }
      const V3 lo = parts::to_vec<3>(k.min_m), hi = parts::to_vec<3>(k.max_m);
      for (int d = 0; d < 3; ++d)
        for (const Real sign : {Real(-1), Real(1)}) {
          Support s;
          s.n[d] = sign;
          s.c = sign * (sign < 0 ? lo[d] : hi[d]);
          s.lo = lo;
          s.hi = hi;
          s.lo[d] = -std::numeric_limits<Real>::infinity();
          s.hi[d] = std::numeric_limits<Real>::infinity();
          supports_.push_back(s);
        }
      for (int m = 0; m < 8; ++m) {
        Support s;
        s.plane = false;
        s.centre = V3(m & 1 ? hi[0] : lo[0], m & 2 ? hi[1] : lo[1], m & 4 ? hi[2] : lo[2]);
        supports_.push_back(s);
      }
    }
  }

  Locus locus(const Support& s, Real r) const {
    Locus l;
    l.plane = s.plane;
    if (s.plane) {
      l.n = s.n;
      l.c = s.c + r;
      l.face = &s;
    } else {
      l.p = s.centre;
      l.R = s.radius + r;
    }
    return l;
  }

  // The crossings of three loci, the planes' extents kept.
  int cross(const Locus& a, const Locus& b, const Locus& c, Points& out) const {
    std::array<const Locus*, 3> l{&a, &b, &c};
    std::stable_partition(l.begin(), l.end(), [](const Locus* q) { return !q->plane; });
    int n = 0;
    const int planes = a.plane + b.plane + c.plane;
    if (planes == 0) {
      n = sphere_sphere_sphere(l[0]->p, l[0]->R, l[1]->p, l[1]->R, l[2]->p, l[2]->R, out);
    } else if (planes == 1) {
      n = sphere_sphere_plane(l[0]->p, l[0]->R, l[1]->p, l[1]->R, l[2]->n, l[2]->c, out);
    } else if (planes == 2) {
      n = sphere_plane_plane(l[0]->p, l[0]->R, l[1]->n, l[1]->c, l[2]->n, l[2]->c, out);
    } else {
      Eigen::Matrix3d m;
      m << l[0]->n.transpose(), l[1]->n.transpose(), l[2]->n.transpose();
      if (std::abs(m.determinant()) < 1e-12) return 0;
      out[0] = m.partialPivLu().solve(V3(l[0]->c, l[1]->c, l[2]->c));
      n = 1;
    }
    int kept = 0;
    for (int q = 0; q < n; ++q) {
      bool on = true;
      for (const Locus* f : l)
        if (f->plane && f->face)
          for (int d = 0; d < 3; ++d)
            on &= out[q][d] >= f->face->lo[d] - eps_ && out[q][d] <= f->face->hi[d] + eps_;
      if (on) out[kept++] = out[q];
    }
    return kept;
  }

  bool fits(const V3& x, Real r) const {
    for (int d = 0; d < 3; ++d)
      if (x[d] < in_.lo[d] + r - eps_ || x[d] > in_.hi[d] - r + eps_) return false;
    for (const parts::RegionConfig& k : in_.keep_clear)
      if (parts::region_distance<3>(k, x) < r - eps_) return false;
    bool clear = true;
    for_near(x, r + in_.r_max, [&](std::int64_t j) {
      const Grain<3>& g = grains_[static_cast<std::size_t>(j)];
      if ((x - g.x).squaredNorm() < (r + g.r - eps_) * (r + g.r - eps_)) clear = false;
    });
    return clear;
  }

  template <class F>
  void for_near(const V3& x, Real reach, F&& f) const {
    std::array<std::int64_t, 3> lo, hi;
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::max<std::int64_t>(
          0, static_cast<std::int64_t>(std::floor((x[d] - reach - in_.lo[d]) / cell_)));
      hi[d] = std::min<std::int64_t>(
          cells_[d] - 1, static_cast<std::int64_t>(std::floor((x[d] + reach - in_.lo[d]) / cell_)));
    }
    for (std::int64_t k = lo[2]; k <= hi[2]; ++k)
      for (std::int64_t j = lo[1]; j <= hi[1]; ++j)
        for (std::int64_t i = lo[0]; i <= hi[0]; ++i)
          for (std::int64_t g =
                   head_[static_cast<std::size_t>((k * cells_[1] + j) * cells_[0] + i)];
               g >= 0; g = next_[static_cast<std::size_t>(g)])
            f(g);
  }

  void consider(const Points& pts, int n, Real r, std::optional<V3>& best) const {
    for (int q = 0; q < n; ++q)
      if ((!best || lower(pts[q], *best)) && fits(pts[q], r)) best = pts[q];
  }

  std::optional<V3> lowest_next_to(std::size_t a, Real r) const {
    const Grain<3>& ga = grains_[a];
    Locus la;
    la.p = ga.x;
    la.R = ga.r + r;
    // The other supports within reach of a grain touching a: grains, then the rest.
    std::vector<Locus> near;
    for_near(ga.x, ga.r + 2 * r + in_.r_max, [&](std::int64_t j) {
      if (static_cast<std::size_t>(j) == a) return;
      const Grain<3>& g = grains_[static_cast<std::size_t>(j)];
      if ((g.x - ga.x).norm() > ga.r + g.r + 2 * r) return;
      Locus l;
      l.p = g.x;
      l.R = g.r + r;
      near.push_back(l);
    });
    for (const Support& s : supports_) {
      const Locus l = locus(s, r);
      const Real gap = l.plane ? std::abs(l.n.dot(ga.x) - l.c) : (l.p - ga.x).norm() - l.R;
      if (gap <= la.R) near.push_back(l);
    }
    std::optional<V3> best;
    Points pts;
    for (std::size_t i = 0; i < near.size(); ++i)
      for (std::size_t j = i + 1; j < near.size(); ++j) {
        const Locus &b = near[i], &c = near[j];
        // Two grains further apart than a grain of radius r can bridge: no common touch.
        if (!b.plane && !c.plane && (b.p - c.p).norm() > b.R + c.R) continue;
        consider(pts, cross(la, b, c, pts), r, best);
      }
    return best;
  }

  std::optional<V3> lowest_on_supports(Real r) const {
    std::vector<Locus> all;
    for (const Support& s : supports_)
      all.push_back(locus(s, r));
    std::optional<V3> best;
    Points pts;
    for (std::size_t i = 0; i < all.size(); ++i)
      for (std::size_t j = i + 1; j < all.size(); ++j)
        for (std::size_t k = j + 1; k < all.size(); ++k)
          consider(pts, cross(all[i], all[j], all[k], pts), r, best);
    return best;
  }

  void place(const V3& x, Real r) {
    if (grains_.size() >= in_.max_grains) throw std::length_error("dense packing: too many grains");
    const auto k = static_cast<std::int64_t>(grains_.size());
    grains_.push_back({x, r});
    std::array<std::int64_t, 3> c;
    for (int d = 0; d < 3; ++d)
      c[d] = std::clamp<std::int64_t>(
          static_cast<std::int64_t>(std::floor((x[d] - in_.lo[d]) / cell_)), 0, cells_[d] - 1);
    const auto cell = static_cast<std::size_t>((c[2] * cells_[1] + c[1]) * cells_[0] + c[0]);
    next_.push_back(head_[cell]);
    head_[cell] = k;
    open_.push({height(x), k});
  }

  const DensePackingInput<3>& in_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<Real> draw_;
  Real eps_;
  Real cell_ = 0;
  std::array<std::int64_t, 3> cells_{};
  std::vector<std::int64_t> head_, next_;
  std::vector<Grain<3>> grains_;
  std::vector<Support> supports_;
  using Open = std::pair<Real, std::int64_t>;
  std::priority_queue<Open, std::vector<Open>, std::greater<Open>> open_;
};

}  // namespace

std::vector<Grain<3>> deposit_spheres(const DensePackingInput<3>& in, DensePackingReport& report) {
  return Deposition3(in).run(report);
}

}  // namespace crater::dem::detail
