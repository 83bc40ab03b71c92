// Contacts between parts; see coupling.hpp.
#include "contact/coupling.hpp"

#include <fmt/format.h>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>

#include "neighbors/neighbor_list.hpp"
#include "parallel/parallel.hpp"

namespace crater::contact {
namespace {

std::size_t at(Index i) {
  return static_cast<std::size_t>(i);
}

template <int D>
AxialVec<D> axial_zero() {
  if constexpr (D == 2) {
    return Real(0);
  } else {
    return AxialVec<D>::Zero();
  }
}

/// Velocity of the point at arm `r` from the centre of a body spinning at w: w x r.
template <int D>
Vec<D> spin_velocity(const AxialVec<D>& w, const Vec<D>& r) {
  if constexpr (D == 2) {
    return Vec<D>(-w * r[1], w * r[0]);
  } else {
    return w.cross(r);
  }
}

/// Moment of force F at arm r: r x F.
template <int D>
AxialVec<D> moment(const Vec<D>& r, const Vec<D>& f) {
  if constexpr (D == 2) {
    return r[0] * f[1] - r[1] * f[0];
  } else {
    return r.cross(f);
  }
}

/// Closest point of a face to x, with the weights of the face's nodes at it.
template <int D>
struct FacePoint {
  Vec<D> point = Vec<D>::Zero();
  std::array<Real, parts::kFaceNodes<D>> weight{};
};

/// Closest point of triangle (a, b, c) to p, as barycentric weights (Ericson, Real-Time
/// Collision Detection, 2005, section 5.1.5).
inline std::array<Real, 3> closest_on_triangle(const Vec<3>& p, const Vec<3>& a, const Vec<3>& b,
                                               const Vec<3>& c) {
  const Vec<3> ab = b - a, ac = c - a, ap = p - a;
  const Real d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Vec<3> bp = p - b;
  const Real d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const Real vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const Real v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const Vec<3> cp = p - c;
  const Real d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const Real vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const Real w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const Real va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const Real w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const Real denom = 1 / (va + vb + vc);
  const Real v = vb * denom, w = vc * denom;
  return {1 - v - w, v, w};
}

template <int D>
FacePoint<D> closest_on_face(const Vec<D>& p, const std::array<Vec<D>, parts::kFaceNodes<D>>& x) {
  FacePoint<D> fp;
  if constexpr (D == 2) {
    const Vec<D> t = x[1] - x[0];
    const Real len2 = t.squaredNorm();
    const Real s = len2 > 0 ? std::clamp((p - x[0]).dot(t) / len2, Real(0), Real(1)) : Real(0);
    fp.weight = {1 - s, s};
    fp.point = x[0] + s * t;
  } else {
    // The quadrilateral as the triangles (0, 1, 2) and (0, 2, 3); the nearer one's point.
    const auto w1 = closest_on_triangle(p, x[0], x[1], x[2]);
    const auto w2 = closest_on_triangle(p, x[0], x[2], x[3]);
    const Vec<3> c1 = w1[0] * x[0] + w1[1] * x[1] + w1[2] * x[2];
    const Vec<3> c2 = w2[0] * x[0] + w2[1] * x[2] + w2[2] * x[3];
    if ((p - c1).squaredNorm() <= (p - c2).squaredNorm()) {
      fp.point = c1;
      fp.weight = {w1[0], w1[1], w1[2], 0};
    } else {
      fp.point = c2;
      fp.weight = {w2[0], 0, w2[1], w2[2]};
    }
  }
  return fp;
}

/// Outward unit normal of a face (numbering of parts::ContactSurface).
template <int D>
Vec<D> face_normal(const std::array<Vec<D>, parts::kFaceNodes<D>>& x) {
  Vec<D> n;
  if constexpr (D == 2) {
    const Vec<D> t = x[1] - x[0];
    n = Vec<D>(t[1], -t[0]);
  } else {
    n = (x[2] - x[0]).cross(x[3] - x[1]);
  }
  const Real len = n.norm();
  return len > 0 ? Vec<D>(n / len) : Vec<D>::Zero();
}

/// Normal and tangential penalty force on side 1 for overlap delta along n (from 2 to 1), the
/// relative velocity v of side 1's contact point, the effective mass m.
template <int D>
Vec<D> penalty_force(Real k, Real delta, const Vec<D>& n, const Vec<D>& v, Real m, Real xi, Real mu,
                     Real& normal) {
  const Real root = std::sqrt(k * m);
  const Real vn = v.dot(n);
  normal = std::max(Real(0), k * delta - 2 * xi * root * vn);
  Vec<D> f = normal * n;
  if (mu > 0 && normal > 0) {
    const Vec<D> vt = v - vn * n;
    const Real speed = vt.norm();
    // The dashpot that regularises sticking: c_t = sqrt(k m*) / 2. The tangential motion of a
    // rolling grain has an effective mass of m / (1 + m r^2 / I), down to m* / 3.5 for a
    // sphere, so a critically damped c_t = 2 sqrt(k m*) would be unstable at the step limit.
    if (speed > 0) f -= (std::min(mu * normal, Real(0.5) * root * speed) / speed) * vt;
  }
  return f;
}

Real reduced_mass(Real a, Real b) {
  if (!(a > 0)) return b;
  if (!(b > 0)) return a;
  return a * b / (a + b);
}

/// Step limit of a penalty spring: omega dt <= 1/2, i.e. at least 12 steps per period. The
/// central-difference stability limit of a damped spring, (2/omega)(sqrt(1 + xi^2) - xi), is
/// ~4x larger, but an impact resolved in two or three steps books its energy badly: an SPH blob
/// hitting a plate at 200 m/s gained 10 % energy at omega dt = 1.6, 0.4 % at 0.8, 0.06 % at
/// 0.36 (tests/verification/contact_conservation).
Real spring_step(Real k, Real m, Real xi) {
  if (!(k > 0) || !(m > 0)) return std::numeric_limits<Real>::infinity();
  const Real omega = std::sqrt(k / m);
  return std::min(Real(0.5) / omega, 2 / omega * (std::sqrt(1 + xi * xi) - xi));
}

}  // namespace

template <int D>
Coupling<D>::Coupling(const io::Config& config,
                      const std::vector<std::unique_ptr<parts::Part<D>>>& parts) {
  for (const auto& c : config.contacts) {
    Pairing p;
    p.config = c;
    const std::string& m0 = config.parts[c.parts[0]].method;
    const std::string& m1 = config.parts[c.parts[1]].method;
    if (m0 == "fem" && m1 == "fem") {
      p.kind = Kind::SurfaceSurface;
      p.points = c.parts[0];
      p.other = c.parts[1];
    } else if (m0 == "fem" || m1 == "fem") {
      p.kind = Kind::ParticleSurface;
      p.points = m0 == "fem" ? c.parts[1] : c.parts[0];
      p.other = m0 == "fem" ? c.parts[0] : c.parts[1];
    } else {
      p.kind = Kind::ParticleParticle;
      p.points = m0 == "sph" ? c.parts[0] : c.parts[1];
      p.other = m0 == "sph" ? c.parts[1] : c.parts[0];
      const auto& g = config.materials[config.parts[p.other].material].granular;
      p.grain_modulus_pa = 2 * g.shear_modulus_pa * (1 + g.poisson_ratio);
    }
    p.name = parts[p.points]->name() + "-" + parts[p.other]->name();
    for (std::size_t k : {p.points, p.other})
      if (std::find(involved_.begin(), involved_.end(), k) == involved_.end())
        involved_.push_back(k);
    pairings_.push_back(p);
  }
  std::sort(involved_.begin(), involved_.end());
}

template <int D>
parts::StableStep Coupling<D>::stable_step(
    const std::vector<std::unique_ptr<parts::Part<D>>>& parts) const {
  parts::StableStep best;
  best.dt_s = std::numeric_limits<Real>::infinity();
  auto consider = [&](Real dt, Index entity, auto&& reason) {
    if (dt < best.dt_s) {
      best.dt_s = dt;
      best.entity_id = entity;
      best.reason = reason();
    }
  };
  for (const auto& p : pairings_) {
    if (p.kind == Kind::SurfaceSurface) {
      const auto sa = parts[p.points]->contact_surface();
      const auto sb = parts[p.other]->contact_surface();
      if (!sa || !sb || sa->face_stiffness->empty() || sb->face_stiffness->empty()) continue;
      auto lightest = [](const parts::ContactSurface<D>& surf) {
        Real m = std::numeric_limits<Real>::infinity();
        for (const auto& face : *surf.faces)
          for (Index n : face)
            if ((*surf.node_mass)[at(n)] > 0) m = std::min(m, (*surf.node_mass)[at(n)]);
        return m;
      };
      const Real k_max =
          p.config.penalty_scale *
          std::min(*std::max_element(sa->face_stiffness->begin(), sa->face_stiffness->end()),
                   *std::max_element(sb->face_stiffness->begin(), sb->face_stiffness->end()));
      consider(
          spring_step(k_max, reduced_mass(lightest(*sa), lightest(*sb)), p.config.damping_ratio),
          -1, [&] {
            return fmt::format("contact '{}': penalty spring of stiffness {:.3g} N/m", p.name,
                               k_max);
          });
      if (!p.load_known || p.load_points.size() != sa->node_mass->size() ||
          p.load_other.size() != sb->node_mass->size())
        measure_load(p, parts);
      for (int side = 0; side < 2; ++side) {
        const std::vector<Real>& load = side == 0 ? p.load_points : p.load_other;
        const std::vector<Real>& mass = side == 0 ? *sa->node_mass : *sb->node_mass;
        for (std::size_t i = 0; i < load.size() && i < mass.size(); ++i) {
          if (!(load[i] > 0) || !(mass[i] > 0)) continue;
          consider(spring_step(load[i], mass[i], p.config.damping_ratio), static_cast<Index>(i),
                   [&] {
                     return fmt::format(
                         "contact '{}': node {} of '{}' held by penalty springs summing to "
                         "{:.3g} N/m",
                         p.name, i, parts[side == 0 ? p.points : p.other]->name(), load[i]);
                   });
        }
      }
      continue;
    }
    const auto pts = parts[p.points]->contact_points();
    if (!pts || pts->mass->empty()) continue;
    const Real m_min = parallel::min_over(static_cast<Index>(pts->mass->size()),
                                          std::numeric_limits<Real>::infinity(),
                                          [&](Index i) { return (*pts->mass)[at(i)]; });
    const std::vector<Real>* other_mass = nullptr;
    if (p.kind == Kind::ParticleSurface) {
      const auto surf = parts[p.other]->contact_surface();
      if (!surf || surf->face_stiffness->empty()) continue;
      other_mass = surf->node_mass;
      const Real k_max = p.config.penalty_scale * *std::max_element(surf->face_stiffness->begin(),
                                                                    surf->face_stiffness->end());
      // The spring joins the particle to a face node, which may be the lighter of the two.
      Real node_min = std::numeric_limits<Real>::infinity();
      for (const auto& face : *surf->faces)
        for (Index n : face)
          if ((*surf->node_mass)[at(n)] > 0)
            node_min = std::min(node_min, (*surf->node_mass)[at(n)]);
      consider(spring_step(k_max, reduced_mass(m_min, node_min), p.config.damping_ratio), -1, [&] {
        return fmt::format("contact '{}': penalty spring of stiffness {:.3g} N/m", p.name, k_max);
      });
    } else {
      const auto grains = parts[p.other]->contact_points();
      if (!grains || grains->radius->empty()) continue;
      other_mass = grains->mass;
      const Real r_max = *std::max_element(grains->radius->begin(), grains->radius->end());
      const Real k_max = p.config.penalty_scale * p.grain_modulus_pa * (D == 3 ? r_max : Real(1));
      const Real m_grain = parallel::min_over(static_cast<Index>(grains->mass->size()),
                                              std::numeric_limits<Real>::infinity(),
                                              [&](Index i) { return (*grains->mass)[at(i)]; });
      consider(spring_step(k_max, std::min(m_min, m_grain), p.config.damping_ratio), -1, [&] {
        return fmt::format("contact '{}': penalty spring of stiffness {:.3g} N/m", p.name, k_max);
      });
    }
    // Bodies pressed by several springs at once (found afresh when particles were removed
    // since the last apply(): the cached sums are per particle index).
    if (!p.load_known || p.load_points.size() != pts->mass->size() ||
        p.load_other.size() != other_mass->size())
      measure_load(p, parts);
    auto summed = [&](const std::vector<Real>& load, const std::vector<Real>& mass,
                      const char* what) {
      const Index n = static_cast<Index>(std::min(load.size(), mass.size()));
      auto step_of = [&](Index i) {
        return load[at(i)] > 0 && mass[at(i)] > 0
                   ? spring_step(load[at(i)], mass[at(i)], p.config.damping_ratio)
                   : std::numeric_limits<Real>::infinity();
      };
      const Real dt = parallel::min_over(n, std::numeric_limits<Real>::infinity(), step_of);
      if (!(dt < best.dt_s)) return;
      // The first body that sets it (min is exact: the same one for any thread count).
      const Index i = parallel::select(n, [&](Index j) { return step_of(j) == dt; }).front();
      consider(dt, i, [&] {
        return fmt::format("contact '{}': {} {} held by penalty springs summing to {:.3g} N/m",
                           p.name, what, i, load[at(i)]);
      });
    };
    summed(p.load_points, *pts->mass, "particle");
    summed(p.load_other, *other_mass,
           p.kind == Kind::ParticleSurface ? "surface node" : "particle of the other part");
  }
  best.absolute = true;  // omega dt <= 1/2 is an accuracy bound (spring_step)
  return best;
}

template <int D>
struct Coupling<D>::SurfaceHit {
  Index particle = -1;
  Index face = -1;
  FacePoint<D> where;
  Vec<D> n = Vec<D>::Zero();  // contact normal, from the surface to the particle
  Real overlap = 0;
};

template <int D>
std::vector<typename Coupling<D>::SurfaceHit> Coupling<D>::surface_hits(
    const parts::ContactPoints<D>& pts, const parts::ContactSurface<D>& surf) const {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto& xn = *surf.node_position;
  const auto& faces = *surf.faces;
  const Index nf = static_cast<Index>(faces.size());
  const Index np = static_cast<Index>(pts.position->size());
  if (nf == 0 || np == 0) return {};

  // Candidates: faces whose centre is within r_max + the largest face half-size.
  std::vector<Vec<D>> centre(at(nf));
  Real half_size = 0;
  for (Index f = 0; f < nf; ++f) {
    Vec<D> c = Vec<D>::Zero();
    for (Index n : faces[at(f)])
      c += xn[at(n)] / Real(kF);
    centre[at(f)] = c;
    for (Index n : faces[at(f)])
      half_size = std::max(half_size, (xn[at(n)] - c).norm());
  }
  const Real r_max = *std::max_element(pts.radius->begin(), pts.radius->end());
  neighbors::NeighborList candidates;
  neighbors::build_cross_list<D>(std::span<const Vec<D>>(*pts.position),
                                 std::span<const Vec<D>>(centre), r_max + half_size, candidates);
  // Only the particles with a candidate face (a few per cent of a soil bed) are looked at.
  const std::vector<Index> near =
      parallel::select(np, [&](Index i) { return !candidates.of(i).empty(); });
  std::vector<SurfaceHit> found(near.size());
  parallel::for_each(static_cast<Index>(near.size()), [&](Index k) {
    const Index i = near[at(k)];
    const Vec<D>& x = (*pts.position)[at(i)];
    const Real r = (*pts.radius)[at(i)];
    SurfaceHit best;
    best.particle = i;
    for (Index f : candidates.of(i)) {
      std::array<Vec<D>, kF> fx;
      for (int q = 0; q < kF; ++q)
        fx[at(q)] = xn[at(faces[at(f)][at(q)])];
      const FacePoint<D> fp = closest_on_face<D>(x, fx);
      const Vec<D> nf_out = face_normal<D>(fx);
      const Vec<D> d = x - fp.point;
      const Real s = d.dot(nf_out);
      Real overlap = 0;
      Vec<D> n;
      if (s >= 0) {
        const Real dist = d.norm();
        overlap = r - dist;
        n = dist > 0 ? Vec<D>(d / dist) : nf_out;
      } else {
        if (s <= -r) continue;  // beyond the reach of this face (e.g. the other side of a plate)
        overlap = r - s;
        n = nf_out;
      }
      if (overlap > best.overlap) {
        best.face = f;
        best.overlap = overlap;
        best.where = fp;
        best.n = n;
      }
    }
    found[at(k)] = best;
  });
  const std::vector<Index> touching = parallel::select(
      static_cast<Index>(found.size()), [&](Index k) { return found[at(k)].face >= 0; });
  std::vector<SurfaceHit> hits(touching.size());
  for (std::size_t k = 0; k < touching.size(); ++k)
    hits[k] = found[at(touching[k])];
  return hits;
}

template <int D>
std::vector<typename Coupling<D>::ParticlePair> Coupling<D>::particle_pairs(
    const parts::ContactPoints<D>& a, const parts::ContactPoints<D>& b) const {
  const Index na = static_cast<Index>(a.position->size());
  const Index nb = static_cast<Index>(b.position->size());
  if (na == 0 || nb == 0) return {};
  const Real ra_max = *std::max_element(a.radius->begin(), a.radius->end());
  const Real rb_max = *std::max_element(b.radius->begin(), b.radius->end());
  neighbors::NeighborList list;
  neighbors::build_cross_list<D>(std::span<const Vec<D>>(*a.position),
                                 std::span<const Vec<D>>(*b.position), ra_max + rb_max, list);
  std::vector<ParticlePair> all(list.indices.size());
  parallel::for_each(na, [&](Index i) {
    const Vec<D>& xi = (*a.position)[at(i)];
    const Real ri = (*a.radius)[at(i)];
    const auto row = list.of(i);
    const auto base = at(list.offsets[at(i)]);
    for (std::size_t q = 0; q < row.size(); ++q) {
      const Index j = row[q];
      const Vec<D> d = xi - (*b.position)[at(j)];
      const Real dist = d.norm();
      const Real overlap = ri + (*b.radius)[at(j)] - dist;
      if (overlap <= 0 || !(dist > 0)) continue;
      all[base + q] = {i, j, overlap, dist, d};
    }
  });
  const std::vector<Index> kept =
      parallel::select(static_cast<Index>(all.size()), [&](Index q) { return all[at(q)].a >= 0; });
  std::vector<ParticlePair> pairs(kept.size());
  parallel::for_each(static_cast<Index>(kept.size()),
                     [&](Index q) { pairs[at(q)] = all[at(kept[at(q)])]; });
  return pairs;
}

template <int D>
void Coupling<D>::measure_load(const Pairing& p,
                               const std::vector<std::unique_ptr<parts::Part<D>>>& parts) const {
  if (p.kind == Kind::SurfaceSurface) {
    const auto sa = parts[p.points]->contact_surface();
    const auto sb = parts[p.other]->contact_surface();
    p.load_points.assign(sa->node_position->size(), 0);
    p.load_other.assign(sb->node_position->size(), 0);
    node_surface(p, *sa, *sb, node_hits(*sa, *sb), p.load_points, p.load_other, nullptr, nullptr,
                 -1);
    node_surface(p, *sb, *sa, node_hits(*sb, *sa), p.load_other, p.load_points, nullptr, nullptr,
                 1);
    p.load_known = true;
    return;
  }
  const auto pts = parts[p.points]->contact_points();
  p.load_points.assign(pts->position->size(), 0);
  if (p.kind == Kind::ParticleSurface) {
    const auto surf = parts[p.other]->contact_surface();
    p.load_other.assign(surf->node_position->size(), 0);
    for (const SurfaceHit& h : surface_hits(*pts, *surf))
      add_surface_load(p, *surf, h);
  } else {
    const auto grains = parts[p.other]->contact_points();
    p.load_other.assign(grains->position->size(), 0);
    for (const ParticlePair& pp : particle_pairs(*pts, *grains))
      add_particle_load(p, *grains, pp);
  }
  p.load_known = true;
}

template <int D>
void Coupling<D>::apply(const std::vector<std::unique_ptr<parts::Part<D>>>& parts, Real dt_s) {
  if (pairings_.empty()) return;
  // Forces per part in any contact: per particle, or per node of a surface.
  std::vector<std::vector<Vec<D>>> force(parts.size());
  std::vector<std::vector<AxialVec<D>>> torque(parts.size());
  for (std::size_t k : involved_) {
    Index n = 0;
    if (const auto pts = parts[k]->contact_points())
      n = static_cast<Index>(pts->position->size());
    else if (const auto surf = parts[k]->contact_surface())
      n = static_cast<Index>(surf->node_position->size());
    force[k].assign(at(n), Vec<D>::Zero());
    if (const auto pts = parts[k]->contact_points(); pts && pts->angular_velocity)
      torque[k].assign(at(n), axial_zero<D>());
  }
  for (auto& p : pairings_) {
    if (p.kind == Kind::SurfaceSurface) {
      const auto sa = parts[p.points]->contact_surface();
      const auto sb = parts[p.other]->contact_surface();
      p.active = 0;
      p.max_overlap_m = 0;
      p.normal_force_n = 0;
      p.force_on_other.setZero();
      p.load_points.assign(sa->node_position->size(), 0);
      p.load_other.assign(sb->node_position->size(), 0);
      for (const NodeSurfaceSums& sums :
           {node_surface(p, *sa, *sb, node_hits(*sa, *sb), p.load_points, p.load_other,
                         &force[p.points], &force[p.other], -1),
            node_surface(p, *sb, *sa, node_hits(*sb, *sa), p.load_other, p.load_points,
                         &force[p.other], &force[p.points], 1)}) {
        p.active += sums.active;
        p.max_overlap_m = std::max(p.max_overlap_m, sums.max_overlap_m);
        p.normal_force_n += sums.normal_force_n;
        p.force_on_other += sums.force_on_other;
      }
      p.load_known = true;
      continue;
    }
    const auto pts = parts[p.points]->contact_points();
    if (p.kind == Kind::ParticleSurface) {
      const auto surf = parts[p.other]->contact_surface();
      particle_surface(p, dt_s, *pts, *surf, force[p.points], torque[p.points], force[p.other]);
    } else {
      const auto grains = parts[p.other]->contact_points();
      particle_particle(p, *pts, *grains, force[p.points], force[p.other], torque[p.other]);
    }
  }
  for (std::size_t k : involved_)
    parts[k]->add_contact_forces(force[k], torque[k]);
}

template <int D>
Real Coupling<D>::surface_stiffness(const Pairing& p, const parts::ContactSurface<D>& surf,
                                    Index face) const {
  return p.config.penalty_scale * (*surf.face_stiffness)[at(face)];
}

template <int D>
Real Coupling<D>::grain_stiffness(const Pairing& p, const parts::ContactPoints<D>& grains,
                                  Index j) const {
  return p.config.penalty_scale * p.grain_modulus_pa * (D == 3 ? (*grains.radius)[at(j)] : Real(1));
}

template <int D>
void Coupling<D>::add_surface_load(const Pairing& p, const parts::ContactSurface<D>& surf,
                                   const SurfaceHit& h) const {
  const Real k = surface_stiffness(p, surf, h.face);
  p.load_points[at(h.particle)] += k;
  const auto& face = (*surf.faces)[at(h.face)];
  for (int q = 0; q < parts::kFaceNodes<D>; ++q)
    p.load_other[at(face[at(q)])] += k * h.where.weight[at(q)];
}

template <int D>
void Coupling<D>::add_particle_load(const Pairing& p, const parts::ContactPoints<D>& grains,
                                    const ParticlePair& pp) const {
  const Real k = grain_stiffness(p, grains, pp.b);
  p.load_points[at(pp.a)] += k;
  p.load_other[at(pp.b)] += k;
}

template <int D>
void Coupling<D>::particle_surface(Pairing& p, Real dt, const parts::ContactPoints<D>& pts,
                                   const parts::ContactSurface<D>& surf,
                                   std::vector<Vec<D>>& f_points,
                                   std::vector<AxialVec<D>>& t_points,
                                   std::vector<Vec<D>>& f_nodes) const {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto& faces = *surf.faces;
  const Index np = static_cast<Index>(pts.position->size());
  p.active = 0;
  p.max_overlap_m = 0;
  p.normal_force_n = 0;
  p.force_on_other.setZero();
  p.load_points.assign(at(np), 0);
  p.load_other.assign(surf.node_position->size(), 0);
  p.load_known = true;
  if (faces.empty() || np == 0) return;

  const std::vector<SurfaceHit> hits = surface_hits(pts, surf);
  const bool offsets = pts.surface_offset && pts.surface_overlap;
  if (offsets) {
    // A particle touching no face has no offset (it starts afresh at its next touch).
    std::vector<char> touching(at(np), 0);
    for (const SurfaceHit& h : hits)
      touching[at(h.particle)] = 1;
    parallel::for_each(np, [&](Index i) {
      if (!touching[at(i)]) (*pts.surface_offset)[at(i)] = -1;
    });
  }
  struct Push {
    Vec<D> force = Vec<D>::Zero();
    Real normal = 0;
  };
  std::vector<Push> push(hits.size());
  parallel::for_each(static_cast<Index>(hits.size()), [&](Index q) {
    const SurfaceHit& h = hits[at(q)];
    const Index i = h.particle;
    const auto& face = faces[at(h.face)];
    Real m_face = 0;
    Vec<D> v_face = Vec<D>::Zero();
    for (int k = 0; k < kF; ++k) {
      m_face += h.where.weight[at(k)] * (*surf.node_mass)[at(face[at(k)])];
      v_face += h.where.weight[at(k)] * (*surf.node_velocity)[at(face[at(k)])];
    }
    Vec<D> v = (*pts.velocity)[at(i)];
    const Real r = (*pts.radius)[at(i)];
    const Vec<D> arm = -r * h.n;
    if (pts.angular_velocity) v += spin_velocity<D>((*pts.angular_velocity)[at(i)], arm);
    Real pushed = h.overlap;
    if (offsets) {
      Real* offset = &(*pts.surface_offset)[at(i)];
      const Real approach = std::abs((v - v_face).dot(h.n)) * dt;
      Real& last = (*pts.surface_overlap)[at(i)];
      if (*offset < 0) {
        // First touch: what the approach over the step cannot explain is ignored.
        *offset = std::max(Real(0), h.overlap - approach);
      } else {
        // In contact already: a jump of the overlap beyond twice the approach is a face that
        // appeared under the particle (the element in front of it eroded) or a deeper face
        // taking over; it joins the offset. (Twice: the approach is measured with the
        // velocity at the end of the step, the overlap grew with the one inside it.)
        *offset += std::max(Real(0), h.overlap - last - 2 * approach);
        *offset = std::min(*offset, h.overlap);
      }
      last = h.overlap;
      pushed = h.overlap - *offset;
    }
    Push& out = push[at(q)];
    out.force = penalty_force<D>(surface_stiffness(p, surf, h.face), pushed, h.n, v - v_face,
                                 reduced_mass((*pts.mass)[at(i)], m_face), p.config.damping_ratio,
                                 p.config.friction, out.normal);
  });

  // Scatter in particle order: the same sums for any thread count.
  for (std::size_t q = 0; q < hits.size(); ++q) {
    const SurfaceHit& h = hits[q];
    const Index i = h.particle;
    const Push& f = push[q];
    ++p.active;
    p.max_overlap_m = std::max(p.max_overlap_m, h.overlap);
    p.normal_force_n += f.normal;
    p.force_on_other -= f.force;
    f_points[at(i)] += f.force;
    // The arm -r n from the centre to the contact point; only the tangential part of the
    // force has a moment about the centre.
    if (!t_points.empty())
      t_points[at(i)] += moment<D>(Vec<D>(-(*pts.radius)[at(i)] * h.n), f.force);
    const auto& face = faces[at(h.face)];
    for (int k = 0; k < kF; ++k)
      f_nodes[at(face[at(k)])] -= h.where.weight[at(k)] * f.force;
    add_surface_load(p, surf, h);
  }
}

template <int D>
void Coupling<D>::particle_particle(Pairing& p, const parts::ContactPoints<D>& a,
                                    const parts::ContactPoints<D>& b, std::vector<Vec<D>>& f_a,
                                    std::vector<Vec<D>>& f_b, std::vector<AxialVec<D>>& t_b) const {
  p.active = 0;
  p.max_overlap_m = 0;
  p.normal_force_n = 0;
  p.force_on_other.setZero();
  p.load_points.assign(a.position->size(), 0);
  p.load_other.assign(b.position->size(), 0);
  p.load_known = true;
  const std::vector<ParticlePair> pairs = particle_pairs(a, b);
  // Per pair results, in list order (a ascending, then b ascending).
  struct PairForce {
    Vec<D> force = Vec<D>::Zero();  // on a
    Vec<D> arm_b = Vec<D>::Zero();  // from b's centre to the contact point
    Real normal = 0;
  };
  std::vector<PairForce> out(pairs.size());
  parallel::for_each(static_cast<Index>(pairs.size()), [&](Index q) {
    const ParticlePair& pp = pairs[at(q)];
    PairForce& pf = out[at(q)];
    const Vec<D> n = pp.d / pp.dist;  // from b to a
    pf.arm_b = (*b.radius)[at(pp.b)] * n;
    Vec<D> v = (*a.velocity)[at(pp.a)] - (*b.velocity)[at(pp.b)];
    if (b.angular_velocity) v -= spin_velocity<D>((*b.angular_velocity)[at(pp.b)], pf.arm_b);
    pf.force = penalty_force<D>(grain_stiffness(p, b, pp.b), pp.overlap, n, v,
                                reduced_mass((*a.mass)[at(pp.a)], (*b.mass)[at(pp.b)]),
                                p.config.damping_ratio, p.config.friction, pf.normal);
  });
  for (std::size_t q = 0; q < pairs.size(); ++q) {
    const ParticlePair& pp = pairs[q];
    const PairForce& pf = out[q];
    ++p.active;
    p.max_overlap_m = std::max(p.max_overlap_m, pp.overlap);
    p.normal_force_n += pf.normal;
    p.force_on_other -= pf.force;
    f_a[at(pp.a)] += pf.force;
    f_b[at(pp.b)] -= pf.force;
    if (!t_b.empty()) t_b[at(pp.b)] += moment<D>(pf.arm_b, Vec<D>(-pf.force));
    add_particle_load(p, b, pp);
  }
}

template <int D>
struct Coupling<D>::NodeHit {
  Index node = -1;
  Index face = -1;
  FacePoint<D> where;
  Vec<D> n = Vec<D>::Zero();  // the face's outward normal
  Real overlap = 0;           // depth behind the face
  Real k = 0;                 // penalty stiffness (without the scale)
};

template <int D>
std::vector<typename Coupling<D>::NodeHit> Coupling<D>::node_hits(
    const parts::ContactSurface<D>& nodes_of, const parts::ContactSurface<D>& faces_of) const {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto& xa = *nodes_of.node_position;
  const auto& xb = *faces_of.node_position;
  const auto& faces = *faces_of.faces;
  // The surface nodes of `nodes_of` that carry mass, ascending, with the stiffest of their
  // own faces.
  std::vector<Real> node_k(xa.size(), 0);
  for (std::size_t f = 0; f < nodes_of.faces->size(); ++f)
    for (Index n : (*nodes_of.faces)[f])
      node_k[at(n)] = std::max(node_k[at(n)], (*nodes_of.face_stiffness)[f]);
  std::vector<Index> nodes;
  for (std::size_t n = 0; n < xa.size(); ++n)
    if (node_k[n] > 0 && (*nodes_of.node_mass)[n] > 0) nodes.push_back(static_cast<Index>(n));
  std::vector<NodeHit> hits(nodes.size());
  const Index nf = static_cast<Index>(faces.size());
  if (nf == 0 || nodes.empty()) return hits;

  std::vector<Vec<D>> centre(at(nf));
  std::vector<Real> size(at(nf));
  Real half_size = 0;
  for (Index f = 0; f < nf; ++f) {
    std::array<Vec<D>, kF> fx;
    Vec<D> c = Vec<D>::Zero();
    for (int k = 0; k < kF; ++k) {
      fx[at(k)] = xb[at(faces[at(f)][at(k)])];
      c += fx[at(k)] / Real(kF);
    }
    centre[at(f)] = c;
    for (int k = 0; k < kF; ++k)
      half_size = std::max(half_size, (fx[at(k)] - c).norm());
    if constexpr (D == 2) {
      size[at(f)] = (fx[1] - fx[0]).norm();
    } else {
      size[at(f)] = std::sqrt(Real(0.5) * (fx[2] - fx[0]).cross(fx[3] - fx[1]).norm());
    }
  }
  std::vector<Vec<D>> x(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i)
    x[i] = xa[at(nodes[i])];
  // A node within half a face's size behind it, projecting onto it, is within
  // sqrt(half_size^2 + (half_size)^2) of its centre.
  neighbors::NeighborList candidates;
  neighbors::build_cross_list<D>(std::span<const Vec<D>>(x), std::span<const Vec<D>>(centre),
                                 Real(1.5) * half_size, candidates);
  parallel::for_each(static_cast<Index>(nodes.size()), [&](Index i) {
    NodeHit best;
    best.node = nodes[at(i)];
    const Vec<D>& p = x[at(i)];
    for (Index f : candidates.of(i)) {
      std::array<Vec<D>, kF> fx;
      for (int k = 0; k < kF; ++k)
        fx[at(k)] = xb[at(faces[at(f)][at(k)])];
      const FacePoint<D> fp = closest_on_face<D>(p, fx);
      const Vec<D> nf_out = face_normal<D>(fx);
      const Vec<D> d = p - fp.point;
      const Real s = d.dot(nf_out);
      const Real len = size[at(f)];
      if (s >= 0 || -s > Real(0.5) * len) continue;
      if ((d - s * nf_out).norm() > Real(0.01) * len) continue;  // projects beside the face
      if (best.face >= 0 && (-s > best.overlap || (-s == best.overlap && f > best.face))) continue;
      best.face = f;
      best.where = fp;
      best.n = nf_out;
      best.overlap = -s;
      best.k = std::min((*faces_of.face_stiffness)[at(f)], node_k[at(best.node)]);
    }
    hits[at(i)] = best;
  });
  return hits;
}

template <int D>
typename Coupling<D>::NodeSurfaceSums Coupling<D>::node_surface(
    const Pairing& p, const parts::ContactSurface<D>& a, const parts::ContactSurface<D>& b,
    const std::vector<NodeHit>& hits, std::vector<Real>& load_a, std::vector<Real>& load_b,
    std::vector<Vec<D>>* f_a, std::vector<Vec<D>>* f_b, Real sign) const {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto& faces = *b.faces;
  NodeSurfaceSums sums;
  std::vector<Vec<D>> push(hits.size(), Vec<D>::Zero());
  std::vector<Real> normal(hits.size(), 0);
  if (f_a)
    parallel::for_each(static_cast<Index>(hits.size()), [&](Index q) {
      const NodeHit& h = hits[at(q)];
      if (h.face < 0) return;
      const auto& face = faces[at(h.face)];
      Real m_face = 0;
      Vec<D> v_face = Vec<D>::Zero();
      for (int k = 0; k < kF; ++k) {
        m_face += h.where.weight[at(k)] * (*b.node_mass)[at(face[at(k)])];
        v_face += h.where.weight[at(k)] * (*b.node_velocity)[at(face[at(k)])];
      }
      const Vec<D> v = (*a.node_velocity)[at(h.node)] - v_face;
      push[at(q)] = penalty_force<D>(p.config.penalty_scale * h.k, h.overlap, h.n, v,
                                     reduced_mass((*a.node_mass)[at(h.node)], m_face),
                                     p.config.damping_ratio, p.config.friction, normal[at(q)]);
    });
  // Scatter in node order: the same sums for any thread count.
  for (std::size_t q = 0; q < hits.size(); ++q) {
    const NodeHit& h = hits[q];
    if (h.face < 0) continue;
    const auto& face = faces[at(h.face)];
    const Real k = p.config.penalty_scale * h.k;
    load_a[at(h.node)] += k;
    for (int j = 0; j < kF; ++j)
      load_b[at(face[at(j)])] += k * h.where.weight[at(j)];
    if (!f_a) continue;
    ++sums.active;
    sums.max_overlap_m = std::max(sums.max_overlap_m, h.overlap);
    sums.normal_force_n += normal[q];
    sums.force_on_other += sign * push[q];
    (*f_a)[at(h.node)] += push[q];
    for (int j = 0; j < kF; ++j)
      (*f_b)[at(face[at(j)])] -= h.where.weight[at(j)] * push[q];
  }
  return sums;
}

template <int D>
std::vector<parts::Diagnostic> Coupling<D>::diagnostics() const {
  std::vector<parts::Diagnostic> d;
  for (const auto& p : pairings_) {
    d.push_back({"contact_" + p.name + "_pairs", static_cast<Real>(p.active)});
    d.push_back({"contact_" + p.name + "_max_overlap_m", p.max_overlap_m});
    d.push_back({"contact_" + p.name + "_normal_force_n", p.normal_force_n});
  }
  return d;
}

template <int D>
std::vector<std::string> Coupling<D>::history_columns() const {
  std::vector<std::string> cols;
  for (const auto& p : pairings_)
    for (int k = 0; k < D; ++k)
      cols.push_back(fmt::format("force_{}_{}", p.name, "xyz"[k]));
  return cols;
}

template <int D>
std::vector<Real> Coupling<D>::history_values() const {
  std::vector<Real> v;
  for (const auto& p : pairings_)
    for (int k = 0; k < D; ++k)
      v.push_back(p.force_on_other[k]);
  return v;
}

template class Coupling<2>;
template class Coupling<3>;

}  // namespace crater::contact
