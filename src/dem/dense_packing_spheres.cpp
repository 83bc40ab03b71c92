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

#include "dem/deposition.hpp"

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

using Support = detail::Support<3>;

// A locus of centres for a grain of radius r: a sphere (centre, radius) or a plane.
struct Locus {
  bool plane = false;
  V3 p = V3::Zero();              // sphere centre
  Real R = 0;                     // sphere radius
  V3 n = V3::Zero();              // plane normal
  Real c = 0;                     // plane offset
  const Support* face = nullptr;  // the plane's support (for its extent)
};

class Spheres final : public Deposition<3, Spheres, 8> {
 public:
  explicit Spheres(const DensePackingInput<3>& in) : Deposition(in), supports_(supports_of(in)) {}

 private:
  friend class Deposition<3, Spheres, 8>;  // calls the two lowest_* below

  Locus locus(const Support& s, Real r) const {
    Locus l;
    l.plane = s.flat;
    if (s.flat) {
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
        if (f->plane && f->face) on &= f->face->on_face(out[q], eps_);
      if (on) out[kept++] = out[q];
    }
    return kept;
  }

  std::optional<V3> lowest_next_to(std::size_t a, Real r) const {
    const Grain<3>& ga = grains_[a];
    Locus la;
    la.p = ga.x;
    la.R = ga.r + r;
    // The other supports within reach of a grain touching a: grains, then the rest. The
    // grains are also all that can be in the way of a place touching a (one in the way of x,
    // |x - ga.x| = ga.r + r, is within ga.r + g.r + 2 r of a), so the test that a place is
    // free looks at them (and a) alone, the one last in the way first.
    std::vector<Locus> near;
    std::vector<std::size_t> in_way{a};
    for_near(ga.x, ga.r + 2 * r + in_.r_max, [&](std::int64_t j) {
      if (static_cast<std::size_t>(j) == a) return;
      const Grain<3>& g = grains_[static_cast<std::size_t>(j)];
      if ((g.x - ga.x).norm() > ga.r + g.r + 2 * r) return;
      Locus l;
      l.p = g.x;
      l.R = g.r + r;
      near.push_back(l);
      in_way.push_back(static_cast<std::size_t>(j));
    });
    std::size_t last_in_way = 0;
    auto free_at = [&](const V3& x) { return fits_among(in_way, last_in_way, x, r); };
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
        consider(pts, cross(la, b, c, pts), best, free_at);
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

  const std::vector<Support> supports_;
};

}  // namespace

std::vector<Grain<3>> deposit_spheres(const DensePackingInput<3>& in, DensePackingReport& report) {
  return Spheres(in).run(report);
}

}  // namespace crater::dem::detail
