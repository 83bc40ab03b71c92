// Unit tests of the contacts between parts (src/contact/), one pairing at a time, over stub
// parts that offer hand-made state views (parts::ContactPoints, parts::ContactSurface). The
// expected values are worked out here from the equations of coupling.hpp's header comment:
//   k = s_p K A^2 / V (particle-surface; surface-surface: s_p min of the two sides'),
//   k = s_p E r_2 (sph-dem, 3D) or s_p E (2D),
//   F_n = max(0, k delta - 2 xi sqrt(k m*) v_n),  F_t = -min(mu F_n, sqrt(k m*)/2 |v_t|) t,
//   dt = 1 / (2 omega),  omega = sqrt(k / m).
// Tolerances: kRel (1e-12 relative) where the code does a few flops on the same numbers;
// sums of forces that cancel are held to kRel times the force.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "contact/coupling.hpp"
#include "contact/registry.hpp"
#include "contact/settings.hpp"
#include "parts/part.hpp"

namespace crater::contact {
namespace {

constexpr Real kRel = 1e-12;

/// A part with no physics: it offers the particles or the surface the test gives it and keeps
/// what the contacts hand back.
template <int D>
class StubPart final : public parts::Part<D> {
 public:
  explicit StubPart(std::string name) : name_(std::move(name)) {}

  // Particles (contact_points) when has_points; grains when rotating.
  bool has_points = false;
  bool rotating = false;
  bool offsets = false;  // keeps surface_offset / surface_overlap
  std::vector<Vec<D>> x, v;
  std::vector<Real> m, r;
  std::vector<AxialVec<D>> w;
  std::vector<std::int64_t> ids;  // the particles' ids (empty: none offered)
  mutable std::vector<Real> offset, last_overlap;
  // A surface (contact_surface) when has_surface.
  bool has_surface = false;
  std::vector<Vec<D>> node_x, node_v;
  std::vector<Real> node_m;
  std::vector<std::array<Index, parts::kFaceNodes<D>>> faces;
  std::vector<Index> face_element;
  std::vector<Real> face_k;                          // K A^2 / V [N/m]
  std::map<std::string, std::vector<Index>> groups;  // mesh groups: their nodes
  // The last add_contact_forces().
  std::vector<Vec<D>> force;
  std::vector<AxialVec<D>> torque;

  const std::string& name() const override { return name_; }
  const char* method() const override { return "stub"; }
  Index count() const override { return static_cast<Index>(has_points ? x.size() : faces.size()); }
  Real mass_kg() const override { return 0; }
  parts::StableStep stable_step() const override { return {}; }
  void compute_forces(Real) override {}
  std::optional<parts::Fault> check() const override { return std::nullopt; }
  void advance(Real, Real) override {}
  void finish_step(Real) override {}
  parts::Energies energies() const override { return {}; }
  parts::Geometry<D> geometry() const override { return {}; }
  std::vector<fields::FieldView> point_fields() const override { return {}; }

  std::optional<parts::ContactPoints<D>> contact_points() const override {
    if (!has_points) return std::nullopt;
    parts::ContactPoints<D> p;
    p.position = &x;
    p.velocity = &v;
    p.mass = &m;
    p.radius = &r;
    if (!ids.empty()) p.id = &ids;
    if (rotating) p.angular_velocity = &w;
    if (offsets) {
      offset.resize(x.size(), -1);
      last_overlap.resize(x.size(), 0);
      p.surface_offset = &offset;
      p.surface_overlap = &last_overlap;
    }
    return p;
  }
  std::optional<parts::ContactSurface<D>> contact_surface() const override {
    if (!has_surface) return std::nullopt;
    parts::ContactSurface<D> s;
    s.node_position = &node_x;
    s.node_velocity = &node_v;
    s.node_mass = &node_m;
    s.faces = &faces;
    s.face_element = &face_element;
    s.face_stiffness = &face_k;
    return s;
  }
  const std::vector<Index>* group_nodes(const std::string& group) const override {
    const auto it = groups.find(group);
    return it == groups.end() ? nullptr : &it->second;
  }
  void add_contact_forces(const std::vector<Vec<D>>& f,
                          const std::vector<AxialVec<D>>& t) override {
    force = f;
    torque = t;
    touched_known = false;
  }
  // The last add_touched_contact_forces()' list (touched_known), else unknown.
  std::vector<Index> touched;
  bool touched_known = false;
  void add_touched_contact_forces(const std::vector<Vec<D>>& f, const std::vector<AxialVec<D>>& t,
                                  std::span<const Index> which) override {
    add_contact_forces(f, t);
    touched.assign(which.begin(), which.end());
    touched_known = true;
  }

 private:
  std::string name_;
};

template <int D>
StubPart<D>& add_part(PartList<D>& parts, const std::string& name) {
  parts.push_back(std::make_unique<StubPart<D>>(name));
  return static_cast<StubPart<D>&>(*parts.back());
}

template <int D>
StubPart<D>& stub(const PartList<D>& parts, std::size_t k) {
  return static_cast<StubPart<D>&>(*parts[k]);
}

/// Particles of radius r and mass m at `x`, at rest (grains: not spinning).
template <int D>
void set_particles(StubPart<D>& p, const std::vector<Vec<D>>& x, Real r, Real m, bool rotating) {
  p.has_points = true;
  p.rotating = rotating;
  p.x = x;
  p.v.assign(x.size(), Vec<D>::Zero());
  p.m.assign(x.size(), m);
  p.r.assign(x.size(), r);
  if constexpr (D == 2) {
    p.w.assign(x.size(), Real(0));
  } else {
    p.w.assign(x.size(), Vec<3>::Zero());
  }
}

ContactSettings settings(std::size_t a, std::size_t b, Real s_p, Real mu) {
  ContactSettings s;
  s.parts = {a, b};
  s.penalty_scale = s_p;
  s.friction = mu;
  s.damping_ratio = 0.1;
  return s;
}

Real diagnostic(const std::vector<parts::Diagnostic>& d, const std::string& name) {
  for (const auto& x : d)
    if (x.name == name) return x.value;
  ADD_FAILURE() << "no diagnostic " << name;
  return std::nan("");
}

// ---- particle-surface ---------------------------------------------------------------------

// The unit square z = 0, 0 <= x, y <= 1, as the top face of a 1 x 1 x 0.5 m element of bulk
// modulus K = 2 GPa: outward normal (x_2 - x_0) x (x_3 - x_1) = (0, 0, 2) -> +z, and
// K A^2 / V = 2e9 * 1 / 0.5 = 4e9 N/m. Node masses 1 kg, at rest.
constexpr Real kBulk = 2e9, kArea = 1.0, kVolume = 0.5;
constexpr Real kFaceK = kBulk * kArea * kArea / kVolume;

void set_unit_square(StubPart<3>& s, Real node_mass) {
  s.has_surface = true;
  s.node_x = {Vec<3>(0, 0, 0), Vec<3>(1, 0, 0), Vec<3>(1, 1, 0), Vec<3>(0, 1, 0)};
  s.node_v.assign(4, Vec<3>::Zero());
  s.node_m.assign(4, node_mass);
  s.faces = {{0, 1, 2, 3}};
  s.face_element = {0};
  s.face_k = {kFaceK};
}

/// A particle part ("balls") and the square ("plate"); the contact lists the plate first, so
/// that the registry has to find the particles on the other side.
PartList<3> ball_and_plate(const std::vector<Vec<3>>& x, Real r, Real m) {
  PartList<3> parts;
  set_unit_square(add_part(parts, "plate"), 1.0);
  set_particles<3>(add_part(parts, "balls"), x, r, m, false);
  return parts;
}

TEST(ContactParticleSurface, NormalForceIsKDeltaAlongTheFaceNormalAndEqualAndOpposite) {
  const Real r = 0.1, delta = 1e-3, s_p = 0.1;
  auto parts = ball_and_plate({Vec<3>(0.3, 0.6, r - delta)}, r, 2.0);
  Coupling<3> c({settings(0, 1, s_p, 0)}, parts);
  c.apply(parts, 0);

  const Real k = s_p * kFaceK;  // 4e8 N/m
  const Real fn = k * delta;    // 4e5 N; at rest, so no damping
  const auto& f = stub(parts, 1).force;
  ASSERT_EQ(f.size(), 1u);
  EXPECT_NEAR(f[0].z(), fn, kRel * fn);
  EXPECT_NEAR(f[0].x(), 0, kRel * fn);  // the closest point's weights carry round-off
  EXPECT_NEAR(f[0].y(), 0, kRel * fn);
  // The opposite on the face's nodes with the weights of the closest point (0.3, 0.6, 0): in
  // the triangle (x_0, x_2, x_3), 0.3 (x_2 - x_0) + 0.3 (x_3 - x_0) -> weights 0.4, 0, 0.3, 0.3.
  const auto& fs = stub(parts, 0).force;
  ASSERT_EQ(fs.size(), 4u);
  const std::array<Real, 4> weight{0.4, 0, 0.3, 0.3};
  Vec<3> sum = f[0];
  for (int j = 0; j < 4; ++j) {
    EXPECT_NEAR(fs[j].z(), -weight[j] * fn, kRel * fn) << "node " << j;
    sum += fs[j];
  }
  EXPECT_LE(sum.norm(), kRel * fn);
  // History: the force on the second part of the contact, the plate (points first: balls-plate).
  EXPECT_EQ(c.history_columns(),
            (std::vector<std::string>{"force_balls-plate_x", "force_balls-plate_y",
                                      "force_balls-plate_z"}));
  EXPECT_NEAR(c.history_values()[2], -fn, kRel * fn);
  const auto d = c.diagnostics();
  EXPECT_EQ(diagnostic(d, "contact_balls-plate_pairs"), 1);
  EXPECT_NEAR(diagnostic(d, "contact_balls-plate_max_overlap_m"), delta, 1e-15);
  EXPECT_NEAR(diagnostic(d, "contact_balls-plate_normal_force_n"), fn, kRel * fn);
}

TEST(ContactParticleSurface, NoForceWhenApartOrBeyondReach) {
  const Real r = 0.1;
  // One just above the face, one through the plate by more than its radius (s <= -r).
  auto parts = ball_and_plate({Vec<3>(0.5, 0.5, r + 1e-6), Vec<3>(0.5, 0.5, -r - 1e-6)}, r, 2.0);
  Coupling<3> c({settings(0, 1, 0.1, 0.5)}, parts);
  c.apply(parts, 0);
  for (const auto& f : stub(parts, 1).force)
    EXPECT_EQ(f, Vec<3>::Zero());
  for (const auto& f : stub(parts, 0).force)
    EXPECT_EQ(f, Vec<3>::Zero());
  EXPECT_EQ(diagnostic(c.diagnostics(), "contact_balls-plate_pairs"), 0);
}

TEST(ContactParticleSurface, FrictionIsCappedAtMuFnAndADashpotBelow) {
  const Real r = 0.1, delta = 1e-3, s_p = 0.1, mu = 0.3, m = 2.0;
  const Real k = s_p * kFaceK, fn = k * delta;
  // m* of the particle (2 kg) and the face at the closest point (sum w_j m_j = 1 kg): 2/3 kg.
  const Real m_star = m * 1.0 / (m + 1.0);
  const Real c_t = 0.5 * std::sqrt(k * m_star);  // 8165 N s/m
  for (const Real u : {1000.0, 0.01}) {          // sliding along +x: capped, then not
    auto parts = ball_and_plate({Vec<3>(0.3, 0.6, r - delta)}, r, m);
    stub(parts, 1).v = {Vec<3>(u, 0, 0)};
    Coupling<3> c({settings(0, 1, s_p, mu)}, parts);
    c.apply(parts, 0);
    const Vec<3> f = stub(parts, 1).force[0];
    const Real ft = std::min(mu * fn, c_t * u);
    EXPECT_NEAR(f.z(), fn, kRel * fn) << "u = " << u;  // v_n = 0: no normal damping
    EXPECT_NEAR(f.x(), -ft, kRel * ft) << "u = " << u;
    EXPECT_LE(-f.x(), mu * f.z() * (1 + kRel)) << "u = " << u;
    Vec<3> sum = f;
    for (const auto& g : stub(parts, 0).force)
      sum += g;
    EXPECT_LE(sum.norm(), kRel * fn) << "u = " << u;
  }
  EXPECT_GT(c_t * 1000.0, mu * fn);  // the first case is capped
  EXPECT_LT(c_t * 0.01, mu * fn);    // the second is not
}

TEST(ContactParticleSurface, PenetrationAtFirstTouchIsNotPushedOut) {
  const Real r = 0.1, delta = 1e-3, s_p = 0.1, m = 2.0;
  auto parts = ball_and_plate({Vec<3>(0.3, 0.6, r - delta)}, r, m);
  auto& balls = stub(parts, 1);
  balls.offsets = true;
  Coupling<3> c({settings(0, 1, s_p, 0)}, parts);
  // First touch at t = 0 (dt = 0: no approach explains the overlap): all of it is offset.
  c.apply(parts, 0);
  EXPECT_EQ(balls.force[0], Vec<3>::Zero());
  EXPECT_NEAR(balls.offset[0], delta, 1e-15);
  // Approaching at 1 m/s over dt = 1e-4 s, 5e-5 m deeper (less than twice the approach): the
  // force acts on that increase only, F_n = k e - 2 xi sqrt(k m*) v_n with v_n = -1 m/s.
  const Real e = 5e-5, dt = 1e-4, v_n = -1.0;
  balls.x[0].z() -= e;
  balls.v[0] = Vec<3>(0, 0, v_n);
  c.apply(parts, dt);
  const Real k = s_p * kFaceK, m_star = m * 1.0 / (m + 1.0);
  const Real fn = k * e - 2 * 0.1 * std::sqrt(k * m_star) * v_n;
  EXPECT_NEAR(balls.force[0].z(), fn, 1e-9 * fn);  // e from positions ~0.1 m: 1e-16 / 5e-5
}

TEST(ContactParticleSurface, StableStepIsHalfOverOmegaOfTheStiffestSpring) {
  const Real s_p = 0.1, k = s_p * kFaceK;
  // Apart: only the pair's spring, on the reduced mass of the lightest particle (2 kg) and the
  // lightest face node (1 kg).
  {
    auto parts = ball_and_plate({Vec<3>(0.5, 0.5, 0.5), Vec<3>(0.2, 0.2, 0.5)}, 0.1, 2.0);
    stub(parts, 1).m[1] = 5.0;
    Coupling<3> c({settings(0, 1, s_p, 0)}, parts);
    const parts::StableStep s = c.stable_step(parts);
    const Real m_star = 2.0 * 1.0 / 3.0;
    const Real expected = 0.5 / std::sqrt(k / m_star);
    EXPECT_NEAR(s.dt_s, expected, kRel * expected);
    EXPECT_EQ(s.entity_id, -1);
    EXPECT_TRUE(s.absolute);
    EXPECT_NE(s.reason.find("penalty spring"), std::string::npos) << s.reason;
  }
  // Four heavy particles pressing the corner node 0 (weight 1 there): the node carries
  // sum k w = 4 k on its 1 kg, omega = sqrt(4 k / 1 kg), stiffer than the pair's spring
  // (m* ~ 1 kg). The same from a fresh search and after apply().
  const Real r = 0.1, delta = 1e-3;
  auto parts = ball_and_plate(std::vector<Vec<3>>(4, Vec<3>(0, 0, r - delta)), r, 1e6);
  Coupling<3> c({settings(0, 1, s_p, 0)}, parts);
  const parts::StableStep fresh = c.stable_step(parts);
  c.apply(parts, 0);
  const parts::StableStep after = c.stable_step(parts);
  for (const parts::StableStep& s : {fresh, after}) {
    const Real expected = 0.5 / std::sqrt(4 * k / 1.0);
    EXPECT_NEAR(s.dt_s, expected, kRel * expected);
    EXPECT_EQ(s.entity_id, 0);
    EXPECT_NE(s.reason.find("surface node 0"), std::string::npos) << s.reason;
  }
  // The particles lifted clear: the sums of the next apply() hold none of the springs that
  // ended, and the pair's spring alone limits the step again (m* of a 1e6 kg particle and the
  // 1 kg node).
  for (Vec<3>& x : stub(parts, 1).x)
    x.z() = 10 * r;
  c.apply(parts, 0);
  const parts::StableStep apart = c.stable_step(parts);
  const Real m_star = 1e6 * 1.0 / (1e6 + 1.0);
  const Real expected = 0.5 / std::sqrt(k / m_star);
  EXPECT_NEAR(apart.dt_s, expected, kRel * expected);
  EXPECT_EQ(apart.entity_id, -1) << apart.reason;
}

// ---- surface-surface ----------------------------------------------------------------------

// 2D. Part "lower": one face x_0 = (2, 0), x_1 = (0, 0): tangent (-2, 0), outward normal
// (t_y, -t_x) / |t| = +y, K A^2 / V = 1e9 N/m. Part "upper": one face (0.9, y), (1.1, y):
// normal -y, 3e9 N/m. Node masses 1 kg. With y = -delta both upper nodes are delta behind the
// lower face and project onto it; the lower nodes project beside the short upper face.
PartList<2> two_surfaces(Real y) {
  PartList<2> parts;
  auto& lower = add_part(parts, "lower");
  lower.has_surface = true;
  lower.node_x = {Vec<2>(2, 0), Vec<2>(0, 0)};
  lower.face_k = {1e9};
  auto& upper = add_part(parts, "upper");
  upper.has_surface = true;
  upper.node_x = {Vec<2>(0.9, y), Vec<2>(1.1, y)};
  upper.face_k = {3e9};
  for (auto* s : {&lower, &upper}) {
    s->node_v.assign(2, Vec<2>::Zero());
    s->node_m.assign(2, 1.0);
    s->faces = {{0, 1}};
    s->face_element = {0};
  }
  return parts;
}

TEST(ContactSurfaceSurface, NodeBehindAFaceIsPushedOutWithTheSmallerStiffness) {
  const Real delta = 1e-3, s_p = 0.1;
  auto parts = two_surfaces(-delta);
  Coupling<2> c({settings(0, 1, s_p, 0.4)}, parts);
  c.apply(parts, 0);
  const Real k = s_p * std::min(1e9, 3e9);  // 1e8 N/m
  const Real fn = k * delta;                // 1e5 N/m per node, along the lower face's normal
  const auto& fu = stub(parts, 1).force;
  const auto& fl = stub(parts, 0).force;
  Vec<2> sum = Vec<2>::Zero();
  for (int j = 0; j < 2; ++j) {
    EXPECT_NEAR(fu[j].y(), fn, kRel * fn);
    EXPECT_EQ(fu[j].x(), 0);
    // Lower nodes: weights 0.45/0.55 (foot 0.9) and 0.55/0.45 (foot 1.1): -fn each.
    EXPECT_NEAR(fl[j].y(), -fn, kRel * fn);
    sum += fu[j] + fl[j];
  }
  EXPECT_LE(sum.norm(), kRel * fn);
  EXPECT_NEAR(c.history_values()[1], 2 * fn, kRel * fn);  // on the second part, "upper"
  EXPECT_EQ(diagnostic(c.diagnostics(), "contact_lower-upper_pairs"), 2);
  // Step: the pair's spring k_max = s_p min(1e9, 3e9) on m* = 1/2 kg is stiffer than any
  // node's sum (k on 1 kg).
  const parts::StableStep s = c.stable_step(parts);
  const Real expected = 0.5 / std::sqrt(k / 0.5);
  EXPECT_NEAR(s.dt_s, expected, kRel * expected);
}

// [[contacts]] surface_groups: a group holding both nodes of the lower face keeps the contact
// as it was, bit for bit; one holding a single node leaves the lower part no face in the
// contact (and so no node of its own either): no force on anyone.
TEST(ContactSurfaceSurface, AGroupRestrictsTheContactToTheFacesWhollyInIt) {
  const Real delta = 1e-3;
  auto forces = [&](const std::string& group, Real& pairs) {
    auto parts = two_surfaces(-delta);
    stub(parts, 0).groups = {{"top", {0, 1}}, {"corner", {0}}};
    ContactSettings s = settings(0, 1, 0.1, 0.4);
    s.surface_group = {group, ""};
    Coupling<2> c({s}, parts);
    c.apply(parts, 0);
    pairs = diagnostic(c.diagnostics(), "contact_lower-upper_pairs");
    std::vector<Vec<2>> f = stub(parts, 0).force;
    for (const auto& x : stub(parts, 1).force)
      f.push_back(x);
    return f;
  };
  Real pairs_all = 0, pairs_top = 0, pairs_corner = 0;
  const auto all = forces("", pairs_all);
  const auto top = forces("top", pairs_top);
  const auto corner = forces("corner", pairs_corner);
  EXPECT_EQ(pairs_all, 2);
  EXPECT_EQ(pairs_top, 2);
  EXPECT_EQ(pairs_corner, 0);
  ASSERT_EQ(all.size(), top.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_NE(all[i], Vec<2>::Zero());
    EXPECT_EQ(top[i], all[i]);
    EXPECT_EQ(corner[i], Vec<2>::Zero());
  }
}

TEST(ContactSurfaceSurface, NoForceWhenInFront) {
  auto parts = two_surfaces(1e-3);
  Coupling<2> c({settings(0, 1, 0.1, 0.4)}, parts);
  c.apply(parts, 0);
  for (std::size_t k : {0u, 1u})
    for (const auto& f : stub(parts, k).force)
      EXPECT_EQ(f, Vec<2>::Zero());
}

// ---- particle-particle (sph-dem) ----------------------------------------------------------

// Coupling keeps its force buffers from step to step and zeroes only the particles it gave a
// force (pairing.hpp, ContactForces::touch): after particles move in and out of contact, what it
// hands over is what a new Coupling hands over for the same state, and the particles it says it
// touched (ascending) include every one with a force.
TEST(ContactCoupling, KeptBuffersHandOverWhatAFreshCouplingDoesAsParticlesComeAndGo) {
  const Real r = 0.1, delta = 1e-3;
  // Four balls over the plate: 0 and 2 touch it; 1 and 3 hover.
  auto parts = ball_and_plate({Vec<3>(0.2, 0.2, r - delta), Vec<3>(0.4, 0.4, r + 0.05),
                               Vec<3>(0.6, 0.6, r - delta), Vec<3>(0.8, 0.8, r + 0.05)},
                              r, 2.0);
  Coupling<3> c({settings(0, 1, 0.1, 0.4)}, parts);
  auto& balls = stub(parts, 1);
  c.apply(parts, 0);
  ASSERT_TRUE(balls.touched_known);
  EXPECT_EQ(balls.touched, (std::vector<Index>{0, 2}));
  // 0 lifts off, 3 lands, 2 stays: the buffers' entry of 0 must be zero again.
  balls.x[0].z() = r + 0.05;
  balls.x[3].z() = r - 2 * delta;
  c.apply(parts, 0);
  const std::vector<Vec<3>> kept = balls.force;
  ASSERT_TRUE(balls.touched_known);
  EXPECT_EQ(balls.touched, (std::vector<Index>{2, 3}));
  Coupling<3> fresh({settings(0, 1, 0.1, 0.4)}, parts);
  fresh.apply(parts, 0);
  ASSERT_EQ(kept.size(), balls.force.size());
  for (std::size_t i = 0; i < kept.size(); ++i)
    EXPECT_EQ(kept[i], balls.force[i]) << "ball " << i;
  EXPECT_EQ(kept[0], Vec<3>::Zero());
  EXPECT_GT(kept[3].z(), 0);
  // A particle more: the buffers are sized again, and the new one has its force.
  balls.x.push_back(Vec<3>(0.5, 0.5, r - delta));
  balls.v.push_back(Vec<3>::Zero());
  balls.m.push_back(2.0);
  balls.r.push_back(r);
  balls.w.push_back(Vec<3>::Zero());
  c.apply(parts, 0);
  EXPECT_EQ(balls.touched, (std::vector<Index>{2, 3, 4}));
  EXPECT_GT(balls.force[4].z(), 0);
}

TEST(ContactParticleParticle, StiffnessIsSpERadiusOfTheGrainIn3D) {
  // Grain (r_2 = 0.02 m) at the origin, listed first; SPH particle (r_1 = 0.01 m) at 0.025 m
  // on x: delta = 0.005 m, n from the grain to the particle = +x.
  const Real r1 = 0.01, r2 = 0.02, delta = 0.005, s_p = 0.1, youngs = 1e9;
  PartList<3> parts;
  set_particles<3>(add_part(parts, "grains"), {Vec<3>::Zero()}, r2, 2.0, true);
  set_particles<3>(add_part(parts, "gas"), {Vec<3>(r1 + r2 - delta, 0, 0)}, r1, 1.0, false);
  ContactSettings cs = settings(0, 1, s_p, 0);
  cs.grain_modulus_pa = {youngs, 0};
  Coupling<3> c({cs}, parts);
  c.apply(parts, 0);
  const Real fn = s_p * youngs * r2 * delta;  // 1e4 N
  const Vec<3> fa = stub(parts, 1).force[0], fb = stub(parts, 0).force[0];
  EXPECT_NEAR(fa.x(), fn, kRel * fn);
  EXPECT_LE((fa + fb).norm(), kRel * fn);
  EXPECT_LE(stub(parts, 0).torque[0].norm(), kRel * fn * r2);  // along the line of centres
  // Named and reported with the SPH part first, the force on the grains.
  EXPECT_NEAR(c.history_values()[0], -fn, kRel * fn);
  EXPECT_EQ(c.history_columns()[0], "force_gas-grains_x");
}

TEST(ContactParticleParticle, SpinningGrainGetsCappedFrictionAndItsMomentIn2D) {
  // 2D: k = s_p E per metre. Grain at the origin spinning at omega = 1e5 rad/s; SPH particle
  // at (r1 + r2 - delta, 0). Contact point velocity of the particle relative to the grain's
  // surface: -omega x (r2 n) = (0, -omega r2); the dashpot (0.5 sqrt(k m*) omega r2 = 8.2e6)
  // exceeds mu F_n = 1.5e5, so F_t = mu F_n along +y on the particle, and the grain gets
  // (r2 n) x (-F) = -mu F_n r2.
  const Real r1 = 0.01, r2 = 0.02, delta = 0.005, s_p = 0.1, youngs = 1e9, mu = 0.3;
  PartList<2> parts;
  set_particles<2>(add_part(parts, "gas"), {Vec<2>(r1 + r2 - delta, 0)}, r1, 1.0, false);
  auto& grains = add_part(parts, "grains");
  set_particles<2>(grains, {Vec<2>::Zero()}, r2, 2.0, true);
  grains.w[0] = 1e5;
  ContactSettings cs = settings(0, 1, s_p, mu);
  cs.grain_modulus_pa = {0, youngs};
  Coupling<2> c({cs}, parts);
  c.apply(parts, 0);
  const Real k = s_p * youngs, fn = k * delta;
  ASSERT_GT(0.5 * std::sqrt(k * (2.0 / 3.0)) * 1e5 * r2, mu * fn);
  const Vec<2> fa = stub(parts, 0).force[0], fb = stub(parts, 1).force[0];
  EXPECT_NEAR(fa.x(), fn, kRel * fn);
  EXPECT_NEAR(fa.y(), mu * fn, kRel * fn);
  EXPECT_LE((fa + fb).norm(), kRel * fn);
  EXPECT_NEAR(stub(parts, 1).torque[0], -mu * fn * r2, kRel * fn * r2);
}

TEST(ContactParticleParticle, NoForceWhenApartAndStepFromTheStiffestGrain) {
  PartList<3> parts;
  set_particles<3>(add_part(parts, "gas"), {Vec<3>::Zero()}, 0.01, 1.0, false);
  set_particles<3>(add_part(parts, "grains"), {Vec<3>(0.031, 0, 0), Vec<3>(0, 0.5, 0)}, 0.02, 2.0,
                   true);
  stub(parts, 1).r[1] = 0.03;
  stub(parts, 1).m[1] = 3.0;
  ContactSettings cs = settings(0, 1, 0.1, 0.3);
  cs.grain_modulus_pa = {0, 1e9};
  Coupling<3> c({cs}, parts);
  c.apply(parts, 0);
  EXPECT_EQ(stub(parts, 0).force[0], Vec<3>::Zero());
  for (const auto& f : stub(parts, 1).force)
    EXPECT_EQ(f, Vec<3>::Zero());
  // k_max = s_p E r_max = 0.1 * 1e9 * 0.03; the mass is the lighter of the lightest particle
  // and the lightest grain (1 kg; the code takes min(m_1, m_2) here, not the reduced mass the
  // header's step rule names, so this checks what runs today).
  const parts::StableStep s = c.stable_step(parts);
  const Real expected = 0.5 / std::sqrt(0.1 * 1e9 * 0.03 / 1.0);
  EXPECT_NEAR(s.dt_s, expected, kRel * expected);
}

TEST(ContactParticleParticle, ABodyIsNamedByItsIdAndEqualStepsGoToTheSmallestId) {
  // Two light particles, each squeezed alike between two heavy grains: their summed springs
  // (2 k on 1 g) set equal steps, below the pair's (k on 1 g). Their ids are 7 and 3, in that
  // order: the step names particle 3, not the index 1 (an index moves at each re-sort, and
  // the first in index order is not the same on every rank).
  PartList<3> parts;
  set_particles<3>(add_part(parts, "gas"), {Vec<3>::Zero(), Vec<3>(0.5, 0, 0)}, 0.01, 1e-3, false);
  set_particles<3>(
      add_part(parts, "grains"),
      {Vec<3>(-0.029, 0, 0), Vec<3>(0.029, 0, 0), Vec<3>(0.471, 0, 0), Vec<3>(0.529, 0, 0)}, 0.02,
      1e3, true);
  stub(parts, 0).ids = {7, 3};
  ContactSettings cs = settings(0, 1, 0.1, 0.3);
  cs.grain_modulus_pa = {0, 1e9};
  Coupling<3> c({cs}, parts);
  c.apply(parts, 0);
  const parts::StableStep s = c.stable_step(parts);
  const Real k = 0.1 * 1e9 * 0.02;
  EXPECT_NEAR(s.dt_s, 0.5 / std::sqrt(2 * k / 1e-3), kRel * s.dt_s);
  EXPECT_EQ(s.entity_id, 3) << s.reason;
  EXPECT_NE(s.reason.find("particle 3 held"), std::string::npos) << s.reason;
}

TEST(StepSearch, EqualStepsGoToTheSmallestIdInAnyOrder) {
  for (const std::vector<Index>& order : {std::vector<Index>{5, 3, 9}, {9, 3, 5}, {3, 9, 5}}) {
    StepSearch s;
    s.consider(2.0, -1, [] { return "none in particular"; });
    for (Index id : order)
      s.consider(1.0, id, [id] { return std::to_string(id); });
    EXPECT_EQ(s.best.entity_id, 3);
    EXPECT_EQ(s.best.reason, "3");
    s.consider(1.0, -1, [] { return "none"; });  // a limit of no body does not displace one
    EXPECT_EQ(s.best.entity_id, 3);
    s.consider(0.5, 11, [] { return "11"; });  // a smaller step wins whatever its id
    EXPECT_EQ(s.best.entity_id, 11);
  }
}

// ---- registration -------------------------------------------------------------------------

TEST(ContactRegistry, KindsComeFromThePartsViewsAndUnservedPairsAreRefused) {
  PartList<2> parts;
  set_particles<2>(add_part(parts, "gas"), {Vec<2>::Zero()}, 0.01, 1.0, false);
  set_particles<2>(add_part(parts, "grains"), {Vec<2>::Zero()}, 0.01, 1.0, true);
  add_part(parts, "plate").has_surface = true;
  set_particles<2>(add_part(parts, "gas2"), {Vec<2>::Zero()}, 0.01, 1.0, false);
  add_part(parts, "nothing");
  EXPECT_EQ(kind_of(*parts[0]), PartKind::Particles);
  EXPECT_EQ(kind_of(*parts[1]), PartKind::RotatingParticles);
  EXPECT_EQ(kind_of(*parts[2]), PartKind::Surface);
  EXPECT_THROW(kind_of(*parts[4]), std::logic_error);
  // The pairing orders its parts by kind: particles first, whatever the scenario's order.
  const auto pp = make_pairing<2>(settings(1, 0, 0.1, 0), parts);
  EXPECT_EQ(pp->points(), 0u);
  EXPECT_EQ(pp->other(), 1u);
  const auto ps = make_pairing<2>(settings(2, 1, 0.1, 0), parts);
  EXPECT_EQ(ps->name(), "grains-plate");
  EXPECT_THROW(make_pairing<2>(settings(0, 3, 0.1, 0), parts), std::logic_error);  // sph-sph
}

}  // namespace
}  // namespace crater::contact
