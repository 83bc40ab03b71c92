// Unit tests of the DEM contact laws (src/dem/laws/). Reference values are hand-computed from
// the closed forms quoted in each header (numbers in the comments); tolerances are rounding
// level (1e-12 relative) unless a comment gives another reason.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <type_traits>
#include <utility>

#include <Eigen/Geometry>

#include "dem/laws/absorbing_wall.hpp"
#include "dem/laws/contact_force.hpp"
#include "dem/laws/contact_geometry.hpp"
#include "dem/laws/hertz_mindlin.hpp"
#include "dem/laws/linear_spring.hpp"
#include "dem/laws/local_damping.hpp"
#include "dem/laws/parallel_bond.hpp"
#include "dem/laws/rate_dependent_friction.hpp"
#include "dem/laws/rolling_resistance.hpp"
#include "dem/laws/tangential_history.hpp"
#include "dem/laws/viscous_damping.hpp"

namespace crater::dem {
namespace {

constexpr Real kPi = std::numbers::pi;
constexpr Real kRoundoff = 1e-12;  // relative; every closed form here is a few flops

// The paper's sand (§III-C): G = 29 GPa, nu = 0.2, rho = 1920 kg/m^3; R = 2.5 mm.
constexpr Real kSandShear = 29e9;
constexpr Real kSandPoisson = 0.2;
constexpr Real kSandDensity = 1920.0;
constexpr Real kSandRadius = 2.5e-3;

ElasticMaterial sand() {
  return ElasticMaterial{.youngs_modulus_pa = youngs_modulus_from_shear(kSandShear, kSandPoisson),
                         .poisson_ratio = kSandPoisson};
}

Real sphere_mass(Real radius) {
  return kSandDensity * 4.0 / 3.0 * kPi * radius * radius * radius;
}

void expect_rel(Real actual, Real expected, Real rel) {
  EXPECT_NEAR(actual, expected, rel * std::abs(expected)) << "expected " << expected;
}

// ------------------------------------------------------------------------------------------
// Effective quantities.

TEST(DemEffectiveQuantities, HandValues) {
  expect_rel(effective_radius(1e-3, 3e-3), 0.75e-3, kRoundoff);
  expect_rel(effective_mass(2.0, 6.0), 1.5, kRoundoff);
  // E = 2 G (1 + nu) = 2 * 29e9 * 1.2.
  expect_rel(sand().youngs_modulus_pa, 69.6e9, kRoundoff);
  // Same material: E* = E / (2 (1 - nu^2)) = 69.6e9 / 1.92; G* = G / (2 (2 - nu)) = 29e9 / 3.6.
  expect_rel(effective_youngs_modulus(sand(), sand()), 36.25e9, kRoundoff);
  expect_rel(effective_shear_modulus(sand(), sand()), 29e9 / 3.6, kRoundoff);
  // Sand on steel (200 GPa, 0.3): 1/E* = 0.96/69.6e9 + 0.91/200e9,
  // 1/G* = 2*1.8*1.2/69.6e9 + 2*1.7*1.3/200e9.
  const ElasticMaterial steel{.youngs_modulus_pa = 200e9, .poisson_ratio = 0.3};
  expect_rel(effective_youngs_modulus(sand(), steel), 54516401917.47344, kRoundoff);
  expect_rel(effective_shear_modulus(sand(), steel), 11880863615.879389, kRoundoff);
  // Rigid wall (E = inf): E* = E/(1 - nu^2) = 72.5 GPa, G* = E/(2 (2 - nu)(1 + nu)) = E/4.32.
  const ElasticMaterial rigid{.youngs_modulus_pa = std::numeric_limits<Real>::infinity(),
                              .poisson_ratio = 0.3};
  expect_rel(effective_youngs_modulus(sand(), rigid), 72.5e9, kRoundoff);
  expect_rel(effective_shear_modulus(sand(), rigid), 69.6e9 / 4.32, kRoundoff);
}

// ------------------------------------------------------------------------------------------
// Geometry and kinematics.

TEST(DemContactGeometry, SphereSphere3DHandValues) {
  // x1 = 0, R1 = 1; x2 = (2.5, 0, 0), R2 = 2: n = -e_x, delta = 0.5, arms 0.75 and 1.75.
  const ContactGeometry<3> g =
      sphere_sphere_geometry<3>(Vec<3>::Zero(), 1.0, Vec<3>(2.5, 0, 0), 2.0);
  EXPECT_TRUE(g.touching());
  EXPECT_NEAR((g.normal - Vec<3>(-1, 0, 0)).norm(), 0.0, kRoundoff);
  EXPECT_NEAR(g.overlap, 0.5, kRoundoff);
  EXPECT_NEAR(g.radius_eff, 2.0 / 3.0, kRoundoff);
  EXPECT_NEAR(g.arm1, 0.75, kRoundoff);
  EXPECT_NEAR(g.arm2, 1.75, kRoundoff);
  // v1 = (1, 2, 0), w1 = 3 e_z; v2 = 0, w2 = -e_z. Contact point (0.75, 0, 0):
  // body 1 there: (1, 2 + 3*0.75, 0); body 2 there: w2 x (-1.75, 0, 0) = (0, 1.75, 0).
  const RelativeVelocity<3> v =
      relative_velocity<3>(g, BodyMotion<3>{Vec<3>(1, 2, 0), Vec<3>(0, 0, 3)},
                           BodyMotion<3>{Vec<3>::Zero(), Vec<3>(0, 0, -1)});
  EXPECT_NEAR((v.at_contact - Vec<3>(1, 2.5, 0)).norm(), 0.0, kRoundoff);
  EXPECT_NEAR(v.normal, -1.0, kRoundoff);  // approaching
  EXPECT_NEAR((v.tangential - Vec<3>(0, 2.5, 0)).norm(), 0.0, kRoundoff);
  EXPECT_NEAR((v.spin - Vec<3>(0, 0, 4)).norm(), 0.0, kRoundoff);
}

TEST(DemContactGeometry, Disk2DMatches3DInPlane) {
  const ContactGeometry<2> g = sphere_sphere_geometry<2>(Vec<2>::Zero(), 1.0, Vec<2>(2.5, 0), 2.0);
  const RelativeVelocity<2> v = relative_velocity<2>(g, BodyMotion<2>{Vec<2>(1, 2), 3.0},
                                                     BodyMotion<2>{Vec<2>::Zero(), -1.0});
  EXPECT_NEAR((v.at_contact - Vec<2>(1, 2.5)).norm(), 0.0, kRoundoff);
  EXPECT_NEAR(v.normal, -1.0, kRoundoff);
  EXPECT_NEAR(v.spin, 4.0, kRoundoff);
  // 2D cross products: w x r = (-w r_y, w r_x); r x F = r_x F_y - r_y F_x.
  EXPECT_NEAR((spin_cross<2>(2.0, Vec<2>(1, 3)) - Vec<2>(-6, 2)).norm(), 0.0, kRoundoff);
  EXPECT_NEAR(moment_of<2>(Vec<2>(1, 3), Vec<2>(4, 5)), 1 * 5 - 3 * 4, kRoundoff);
}

TEST(DemContactGeometry, SphereWall) {
  // Sphere of radius 1 at height 0.9 above the plane y = 0: n = e_y, delta = 0.1, arm 0.9, R* = R.
  const ContactGeometry<3> g = sphere_wall_geometry<3>(Vec<3>(0.3, 0.9, 0), 1.0, Vec<3>(0.3, 0, 0));
  EXPECT_NEAR((g.normal - Vec<3>(0, 1, 0)).norm(), 0.0, kRoundoff);
  EXPECT_NEAR(g.overlap, 0.1, kRoundoff);
  EXPECT_NEAR(g.arm1, 0.9, kRoundoff);
  EXPECT_EQ(g.arm2, 0.0);
  EXPECT_EQ(g.radius_eff, 1.0);
}

/// Contact forces conserve angular momentum: tau_1 + tau_2 + x_1 x F + x_2 x (-F) = 0, because
/// the lever arms a_i = R_i - delta/2 add up to the centre distance.
template <int D>
void check_angular_momentum_balance() {
  Vec<D> x1 = Vec<D>::Zero();
  Vec<D> x2 = Vec<D>::Zero();
  x1(0) = 0.1e-3;
  x1(1) = 0.2e-3;
  x2(0) = 4.0e-3;
  x2(1) = 1.1e-3;
  const Real r1 = 2.5e-3;
  const Real r2 = 1.7e-3;
  const ContactGeometry<D> g = sphere_sphere_geometry<D>(x1, r1, x2, r2);
  ASSERT_TRUE(g.touching());
  BodyMotion<D> b1;
  BodyMotion<D> b2;
  b1.velocity(1) = 0.3;
  b2.velocity(0) = 0.2;
  if constexpr (D == 2) {
    b1.angular_velocity = 40.0;
  } else {
    b1.angular_velocity = Vec<3>(10.0, -20.0, 40.0);
  }
  const RelativeVelocity<D> v = relative_velocity<D>(g, b1, b2);
  const HertzMindlinParams p = hertz_mindlin_params(sand(), sand(), 0.5, 0.8);
  const ContactForce<D> c =
      hertz_mindlin<D>(p, g, v, effective_mass(1e-4, 2e-5), Vec<D>::Zero(), 1e-7);
  ASSERT_GT(c.tangential_force.norm(), 0.0);
  const AngularVec<D> total = c.torque_on_1 + c.torque_on_2 + moment_of<D>(x1, c.force_on_1) +
                              moment_of<D>(x2, Vec<D>(-c.force_on_1));
  const Real scale = c.force_on_1.norm() * (x1 - x2).norm();
  EXPECT_LT(angular_norm<D>(total), kRoundoff * scale);
}

TEST(DemContactGeometry, TorquesConserveAngularMomentum) {
  check_angular_momentum_balance<2>();
  check_angular_momentum_balance<3>();
}

// ------------------------------------------------------------------------------------------
// Hertz-Mindlin.

TEST(DemHertzMindlin, NormalForceStiffnessAndEnergyClosedForm) {
  const Real e_eff = effective_youngs_modulus(sand(), sand());
  const Real r_eff = effective_radius(kSandRadius, kSandRadius);
  const Real delta = 2e-6;
  const NormalForce f = hertz_normal_spring(e_eff, r_eff, delta);
  // F = (4/3) E* sqrt(R*) delta^{3/2}: 4/3 * 36.25e9 * sqrt(1.25e-3) * (2e-6)^1.5 = 4.8333 N.
  const Real expected = 4.0 / 3.0 * 36.25e9 * std::sqrt(1.25e-3) * std::pow(2e-6, 1.5);
  expect_rel(f.elastic_force, expected, kRoundoff);
  expect_rel(f.force, expected, kRoundoff);
  expect_rel(f.elastic_energy, 8.0 / 15.0 * 36.25e9 * std::sqrt(1.25e-3) * std::pow(2e-6, 2.5),
             kRoundoff);
  // Stiffness and energy against central differences with h = 1e-4 delta: truncation
  // (h/delta)^2 ~ 1e-8 relative, round-off 1e-16/1e-4 = 1e-12, so 1e-7 is safe.
  const Real h = 1e-4 * delta;
  const NormalForce plus = hertz_normal_spring(e_eff, r_eff, delta + h);
  const NormalForce minus = hertz_normal_spring(e_eff, r_eff, delta - h);
  expect_rel(f.stiffness, (plus.elastic_force - minus.elastic_force) / (2 * h), 1e-7);
  expect_rel(f.elastic_force, (plus.elastic_energy - minus.elastic_energy) / (2 * h), 1e-7);
  expect_rel(f.stiffness, 2.0 * 36.25e9 * std::sqrt(1.25e-3 * 2e-6), kRoundoff);
  // No force without overlap.
  EXPECT_EQ(hertz_normal_spring(e_eff, r_eff, -1e-6).force, 0.0);

  // Through the full law, e = 1 (no dashpot), at rest: F_n is the spring force, along n.
  const Vec<3> x2(2 * kSandRadius - delta, 0, 0);
  const ContactGeometry<3> g =
      sphere_sphere_geometry<3>(Vec<3>::Zero(), kSandRadius, x2, kSandRadius);
  const ContactForce<3> c = hertz_mindlin<3>(hertz_mindlin_params(sand(), sand(), 1.0, 0.5), g,
                                             RelativeVelocity<3>{}, 1e-4, Vec<3>::Zero(), 1e-7);
  expect_rel(c.normal_force, expected, 1e-9);  // delta recomputed from positions: 1e-9 rel
  EXPECT_NEAR((c.force_on_1 - c.normal_force * Vec<3>(-1, 0, 0)).norm(), 0.0, 1e-12);
  expect_rel(c.normal_stiffness, f.stiffness, 1e-9);
}

TEST(DemHertzMindlin, DampingCoefficientsAreLiggghtsFormula) {
  // LIGGGHTS normal_model_hertz.h, written out independently here:
  //   beta = ln e / sqrt(ln^2 e + pi^2), gamma = -2 sqrt(5/6) beta sqrt(S m*),
  //   S_n = 2 E* sqrt(R* delta), S_t = 8 G* sqrt(R* delta), Fn = kn delta - gamma_n v_n.
  const Real e = 0.5;
  const Real m_eff = 0.5 * sphere_mass(kSandRadius);
  const Real delta = 3e-6;
  const HertzMindlinParams p = hertz_mindlin_params(sand(), sand(), e, 10.0);
  ContactGeometry<3> g;
  g.normal = Vec<3>(0, 0, 1);
  g.overlap = delta;
  g.radius_eff = kSandRadius / 2;
  g.arm1 = g.arm2 = kSandRadius - delta / 2;
  RelativeVelocity<3> v;
  v.normal = -0.3;
  v.tangential = Vec<3>(0.2, 0, 0);
  v.at_contact = v.tangential + v.normal * g.normal;
  const Real dt = 1e-8;
  const ContactForce<3> c = hertz_mindlin<3>(p, g, v, m_eff, Vec<3>::Zero(), dt);

  const Real beta = std::log(e) / std::sqrt(std::log(e) * std::log(e) + kPi * kPi);
  const Real sqrt_rd = std::sqrt(g.radius_eff * delta);
  const Real s_n = 2 * 36.25e9 * sqrt_rd;
  const Real s_t = 8 * (29e9 / 3.6) * sqrt_rd;
  const Real gamma_n = -2 * std::sqrt(5.0 / 6.0) * beta * std::sqrt(s_n * m_eff);
  const Real gamma_t = -2 * std::sqrt(5.0 / 6.0) * beta * std::sqrt(s_t * m_eff);
  const Real f_el = 4.0 / 3.0 * 36.25e9 * sqrt_rd * delta;
  expect_rel(c.normal_force, f_el - gamma_n * v.normal, kRoundoff);
  EXPECT_GT(c.normal_force, f_el);  // approaching: the dashpot pushes apart
  // Fresh contact: xi = v_t dt, F_t = -S_t v_t dt - gamma_t v_t (mu = 10: sticking).
  const Vec<3> expected_t = -s_t * v.tangential * dt - gamma_t * v.tangential;
  EXPECT_FALSE(c.sliding);
  EXPECT_NEAR((c.tangential_force - expected_t).norm(), 0.0, kRoundoff * expected_t.norm());
  EXPECT_NEAR((c.shear_history - v.tangential * dt).norm(), 0.0, kRoundoff * 0.2 * dt);
  // Dissipated power: gamma_n v_n^2 + gamma_t |v_t|^2.
  expect_rel(c.dissipated_power, gamma_n * 0.09 + gamma_t * 0.04, 1e-10);
  // Tangential damping off: F_t is the spring alone.
  HertzMindlinParams no_t = p;
  no_t.tangential_damping = false;
  const ContactForce<3> c2 = hertz_mindlin<3>(no_t, g, v, m_eff, Vec<3>::Zero(), dt);
  EXPECT_NEAR((c2.tangential_force + s_t * v.tangential * dt).norm(), 0.0,
              kRoundoff * s_t * 0.2 * dt);
  // LIGGGHTS' beta is minus our damping ratio; e = 1 gives no damping.
  expect_rel(p.damping_ratio, -beta, kRoundoff);
  EXPECT_EQ(damping_ratio_from_restitution(1.0), 0.0);
}

/// Constant tangential displacement rate at fixed overlap, no dashpot (e = 1): the spring loads
/// as F_t = k_t xi = k_t v t until mu F_n, then slides at mu F_n with xi = mu F_n / k_t; reversed,
/// it unloads elastically with the same k_t from +mu F_n to -mu F_n.
template <int D>
void check_stick_then_slide() {
  const Real mu = 0.5;
  const Real delta = 2e-6;
  const HertzMindlinParams p = hertz_mindlin_params(sand(), sand(), 1.0, mu);
  ContactGeometry<D> g;
  g.normal = Vec<D>::Unit(0);
  g.overlap = delta;
  g.radius_eff = kSandRadius / 2;
  g.arm1 = g.arm2 = kSandRadius - delta / 2;
  RelativeVelocity<D> v;
  const Real speed = 1e-2;  // m/s
  v.tangential = speed * Vec<D>::Unit(1);
  v.at_contact = v.tangential;
  const Real dt = 1.17e-6;
  const Real k_t = 8 * (29e9 / 3.6) * std::sqrt(g.radius_eff * delta);
  const Real f_n = 4.0 / 3.0 * 36.25e9 * std::sqrt(g.radius_eff * delta) * delta;
  const Real limit = mu * f_n;
  // mu F_n / k_t = 0.5 * (4/3) E* delta / (8 G*) = 0.75 delta (E*/G* = 4.5 for nu = 0.2), so
  // 7.5e-7 m / (v dt = 1.17e-8 m) = 64.1 steps of sticking.
  const int steps_to_slide = static_cast<int>(limit / (k_t * speed * dt));
  ASSERT_GT(steps_to_slide, 20);

  Vec<D> xi = Vec<D>::Zero();
  int first_sliding_step = -1;
  for (int k = 1; k <= 2 * steps_to_slide; ++k) {
    const ContactForce<D> c = hertz_mindlin<D>(p, g, v, 1e-4, xi, dt);
    xi = c.shear_history;
    const Real f_t = c.tangential_force.norm();
    EXPECT_LT(c.tangential_force.dot(v.tangential), 0.0);  // opposes the motion
    EXPECT_LE(f_t, limit * (1 + kRoundoff));
    if (k * k_t * speed * dt < limit * (1 - 1e-9)) {
      EXPECT_FALSE(c.sliding) << "step " << k;
      expect_rel(f_t, k_t * speed * dt * k, 1e-10);
    } else if (k * k_t * speed * dt > limit * (1 + 1e-9)) {
      EXPECT_TRUE(c.sliding) << "step " << k;
      expect_rel(f_t, limit, kRoundoff);
      expect_rel(xi.norm(), limit / k_t, kRoundoff);
      if (first_sliding_step < 0) first_sliding_step = k;
    }
  }
  EXPECT_EQ(first_sliding_step, steps_to_slide + 1);

  // Reverse: unloads elastically, F_t(j) = mu F_n - k_t v dt j (along +v), until -mu F_n.
  RelativeVelocity<D> back = v;
  back.tangential = -v.tangential;
  back.at_contact = back.tangential;
  for (int j = 1; j < 2 * steps_to_slide; ++j) {
    const ContactForce<D> c = hertz_mindlin<D>(p, g, back, 1e-4, xi, dt);
    xi = c.shear_history;
    const Real signed_force = -c.tangential_force.dot(v.tangential) / speed;  // + = against v
    EXPECT_FALSE(c.sliding) << "reverse step " << j;
    EXPECT_NEAR(signed_force, limit - k_t * speed * dt * j, 1e-9 * limit) << "reverse step " << j;
  }
}

TEST(DemTangentialSpring, LoadsElasticallyThenSlidesAtCoulombLimit) {
  check_stick_then_slide<2>();
  check_stick_then_slide<3>();
}

TEST(DemTangentialSpring, CoulombBoundHoldsWithDashpot) {
  // e = 0.3 (strong dashpot) and a fast tangential motion: LIGGGHTS would let the dashpot push
  // |F_t| above mu F_n while the spring sticks; here the total never exceeds the limit.
  const Real mu = 0.3;
  const HertzMindlinParams p = hertz_mindlin_params(sand(), sand(), 0.3, mu);
  ContactGeometry<3> g;
  g.normal = Vec<3>(0, 0, 1);
  g.overlap = 1e-6;
  g.radius_eff = kSandRadius / 2;
  g.arm1 = g.arm2 = kSandRadius;
  RelativeVelocity<3> v;
  v.tangential = Vec<3>(3.0, -1.0, 0);
  v.at_contact = v.tangential;
  Vec<3> xi = Vec<3>::Zero();
  bool capped_while_sticking = false;
  for (int k = 0; k < 200; ++k) {
    const ContactForce<3> c = hertz_mindlin<3>(p, g, v, 0.5 * sphere_mass(kSandRadius), xi, 1e-9);
    xi = c.shear_history;
    EXPECT_LE(c.tangential_force.norm(), mu * std::abs(c.normal_force) * (1 + kRoundoff));
    EXPECT_GE(c.dissipated_power, 0.0);
    if (!c.sliding && c.tangential_force.norm() >= mu * std::abs(c.normal_force) * (1 - 1e-12)) {
      capped_while_sticking = true;
    }
  }
  EXPECT_TRUE(capped_while_sticking);  // the case the cap exists for did occur
}

// The rate-dependent friction's pair loop takes a contact's force at mu_s first and pays for
// mu_dyn >= mu_s only where the Coulomb limit decided it (ContactForce::limited): below it the
// force must not depend on mu at all, bit for bit, and must not be limited at the larger mu.
TEST(DemTangentialSpring, UnlimitedForceDoesNotDependOnFriction) {
  const HertzMindlinParams low = hertz_mindlin_params(sand(), sand(), 0.3, 0.3);
  const HertzMindlinParams high = hertz_mindlin_params(sand(), sand(), 0.3, 0.45);
  ContactGeometry<3> g;
  g.normal = Vec<3>(0, 0, 1);
  g.overlap = 1e-6;
  g.radius_eff = kSandRadius / 2;
  g.arm1 = g.arm2 = kSandRadius;
  const Real m = 0.5 * sphere_mass(kSandRadius);
  int sliding = 0, capped = 0, free = 0;
  // A slow drag that slides, reversed; then a fast one whose dashpot the limit cuts back while
  // the spring sticks (CoulombBoundHoldsWithDashpot).
  for (const auto& [speed, dt] : {std::pair{0.02, 1e-7}, std::pair{3.0, 1e-9}}) {
    RelativeVelocity<3> v;
    v.at_contact = v.tangential = Vec<3>(speed, -speed / 2, 0);
    Vec<3> xi = Vec<3>::Zero();
    for (int k = 0; k < 400; ++k) {
      v.normal = 0.01 * std::sin(0.05 * k);  // the dashpot pushes and pulls
      if (k == 200) v.at_contact = v.tangential = -v.tangential;
      const ContactForce<3> a = hertz_mindlin<3>(low, g, v, m, xi, dt);
      const ContactForce<3> b = hertz_mindlin<3>(high, g, v, m, xi, dt);
      xi = b.shear_history;
      if (a.limited) {
        ++(a.sliding ? sliding : capped);
        continue;
      }
      EXPECT_FALSE(a.sliding) << "step " << k;
      ++free;
      EXPECT_FALSE(b.limited) << "step " << k;
      EXPECT_EQ(a.force_on_1, b.force_on_1) << "step " << k;
      EXPECT_EQ(a.shear_history, b.shear_history) << "step " << k;
      EXPECT_EQ(a.elastic_energy, b.elastic_energy) << "step " << k;
      EXPECT_EQ(a.dissipated_power, b.dissipated_power) << "step " << k;
    }
  }
  EXPECT_GT(sliding, 0);  // every case occurred
  EXPECT_GT(capped, 0);
  EXPECT_GT(free, 0);
}

TEST(DemTangentialSpring, SlidingDissipatesFrictionTimesSlipSpeed) {
  // A contact dragged at constant speed under a constant normal force: once it slides, the
  // power lost is the friction force times the slip speed, mu F_n |v| (Coulomb), at every
  // step; at mu = 0 nothing is lost. Over the whole drag, loss + stored energy = the work of
  // the force on the displacement with velocity Verlet's rule (the mean of each step's first
  // and last force). The former bookkeeping, the whole cut-back energy, gave
  // mu F_n |v| + (1/2) k |v|^2 dt: 5 % too much here.
  const Real k = 2e5, f_n = 0.1, dt = 1e-6, speed = 0.2;
  const Vec<3> n(0, 0, 1), v(speed * 0.6, speed * 0.8, 0);
  for (const Real mu : {0.0, 0.5}) {
    const TangentialSpring spring{.stiffness = k, .damping = 0, .friction = mu};
    Vec<3> xi = Vec<3>::Zero(), force = Vec<3>::Zero();
    Real lost = 0, work = 0, stored = 0;
    int sliding = 0;
    for (int step = 0; step < 40; ++step) {
      const TangentialForce<3> t = history_tangential_force<3>(spring, f_n, n, v, xi, dt);
      work -= 0.5 * (force + t.force).dot(v) * dt;  // on the contact, by the bodies
      lost += t.dissipated_power * dt;
      stored = t.elastic_energy;
      if (t.sliding && step > 1) {  // steps 0 and 1 load the spring, step 1 slides part way
        ++sliding;
        EXPECT_NEAR(t.dissipated_power, mu * f_n * speed, 1e-12 * (f_n * speed)) << step;
      }
      xi = t.history;
      force = t.force;
    }
    EXPECT_EQ(sliding, 38);  // k |v| dt = 0.04 N a step against a limit of 0.05 N
    EXPECT_NEAR(lost + stored, work, 1e-14);
  }
}

TEST(DemTangentialSpring, HistoryRotationKeepsMagnitudeInTangentPlane) {
  // 3D: xi in the plane normal to n_old; n turns by 10 degrees about an oblique axis.
  const Vec<3> n_old = Vec<3>(1, 2, 2).normalized();
  Vec<3> xi = Vec<3>(3e-6, -1e-6, 0.5e-6);
  xi -= xi.dot(n_old) * n_old;
  const Eigen::AngleAxis<Real> turn(10.0 * kPi / 180.0, Vec<3>(0.3, -1, 0.2).normalized());
  const Vec<3> n_new = turn * n_old;
  const Vec<3> rotated = rotate_into_tangent_plane(xi, n_new);
  EXPECT_LT(std::abs(rotated.dot(n_new)), kRoundoff * xi.norm());
  expect_rel(rotated.norm(), xi.norm(), kRoundoff);
  // Plain projection (LIGGGHTS) would have shrunk it: the rotation is doing something.
  EXPECT_LT((xi - xi.dot(n_new) * n_new).norm(), xi.norm() * (1 - 1e-4));

  // 2D: the tangent line; xi keeps its length and side.
  const Vec<2> n2_new(std::cos(0.2), std::sin(0.2));
  const Vec<2> xi2(0.0, 2e-6);  // tangent to n = e_x
  const Vec<2> r2 = rotate_into_tangent_plane(xi2, n2_new);
  EXPECT_LT(std::abs(r2.dot(n2_new)), kRoundoff * 2e-6);
  expect_rel(r2.norm(), 2e-6, kRoundoff);
  EXPECT_GT(r2.y(), 0.0);

  // Through the law (no relative motion, sticking): the stored history comes back rotated.
  const HertzMindlinParams p = hertz_mindlin_params(sand(), sand(), 0.5, 10.0);
  ContactGeometry<3> g;
  g.normal = n_new;
  g.overlap = 2e-6;
  g.radius_eff = kSandRadius / 2;
  g.arm1 = g.arm2 = kSandRadius;
  const ContactForce<3> c = hertz_mindlin<3>(p, g, RelativeVelocity<3>{}, 1e-4, xi, 1e-7);
  EXPECT_LT(std::abs(c.shear_history.dot(n_new)), kRoundoff * xi.norm());
  expect_rel(c.shear_history.norm(), xi.norm(), kRoundoff);
  EXPECT_LT(std::abs(c.tangential_force.dot(n_new)), kRoundoff * c.tangential_force.norm());
}

// ------------------------------------------------------------------------------------------
// Linear spring-dashpot.

TEST(DemLinearSpring, RestitutionFormula) {
  // zeta(0.5) = ln 2 / sqrt(pi^2 + ln^2 2) = 0.2154537619662468.
  expect_rel(damping_ratio_from_restitution(0.5), 0.2154537619662468, kRoundoff);
  for (Real e : {0.1, 0.3, 0.5, 0.9, 0.99}) {
    expect_rel(restitution_from_damping_ratio(damping_ratio_from_restitution(e)), e, kRoundoff);
  }
  EXPECT_EQ(damping_ratio_from_restitution(0.0), 1.0);

  // Integrate a head-on collision of two equal spheres with the law (velocity Verlet, dashpot
  // fed the half-step velocity, 20000 steps per contact): the rebound speed ratio is e and the
  // duration pi / omega_d. The half-step velocity makes the dashpot O(dt) early; measured
  // error ~1e-4, so 1e-3 leaves margin.
  const Real kn = 1e6;
  const Real m = 1e-3;
  const Real m_eff = 0.5 * m;
  for (Real e : {0.3, 0.5, 0.9}) {
    const LinearSpringParams p = linear_spring_params(kn, 0.5 * kn, e, 0.5);
    const Real tc = linear_spring_contact_time(kn, m_eff, p.damping_ratio);
    const Real dt = tc / 20000;
    const Real r = 1e-3;
    Vec<3> x1(0, 0, 0);
    Vec<3> x2(2 * r, 0, 0);
    Vec<3> v1(0.5, 0, 0);
    Vec<3> v2(-0.5, 0, 0);
    Vec<3> f1 = Vec<3>::Zero();
    Real t = 0;
    Real prev_overlap = 0;
    Real t_end = -1;
    for (int k = 0; k < 40000 && t_end < 0; ++k) {
      v1 += 0.5 * dt * f1 / m;
      v2 -= 0.5 * dt * f1 / m;
      x1 += dt * v1;
      x2 += dt * v2;
      t += dt;
      const ContactGeometry<3> g = sphere_sphere_geometry<3>(x1, r, x2, r);
      if (g.touching()) {
        const RelativeVelocity<3> rv = relative_velocity<3>(g, BodyMotion<3>{v1, Vec<3>::Zero()},
                                                            BodyMotion<3>{v2, Vec<3>::Zero()});
        f1 = linear_spring<3>(p, g, rv, m_eff, Vec<3>::Zero(), dt).force_on_1;
      } else {
        f1.setZero();
        if (prev_overlap > 0) t_end = t - dt * g.overlap / (g.overlap - prev_overlap);
      }
      v1 += 0.5 * dt * f1 / m;
      v2 -= 0.5 * dt * f1 / m;
      prev_overlap = g.overlap;
    }
    ASSERT_GT(t_end, 0.0);
    const Real e_measured = (v2 - v1).x() / 1.0;
    RecordProperty("linear_e" + std::to_string(e), std::to_string(e_measured));
    expect_rel(e_measured, e, 1e-3);
    expect_rel(t_end, tc, 1e-3);
  }
}

// ------------------------------------------------------------------------------------------
// Rolling resistance.

TEST(DemRollingResistance, SpringTorqueCapsAtLimit) {
  // mu_r = 0.1, R* = 1.25 mm, F_n = 10 N, k_n = 1e6 N/m:
  //   k_r = 2.25 * 1e6 * 0.01 * 1.5625e-6 = 3.515625e-2 N m/rad, M_m = 0.1 * 1.25e-3 * 10 N m.
  const RollingResistanceParams p{.friction = 0.1, .damping_ratio = 0.0};
  ContactGeometry<3> g;
  g.normal = Vec<3>(1, 0, 0);
  g.overlap = 1e-6;
  g.radius_eff = 1.25e-3;
  RelativeVelocity<3> v;
  v.spin = Vec<3>(2.0, 5.0, 0.0);  // the 2 rad/s about n is twist, not rolling
  const RollingLoad load{.normal_force = 10.0, .normal_stiffness = 1e6, .inertia_eff = 0.0};
  const Real k_r = 3.515625e-2;
  expect_rel(rolling_stiffness(p.friction, load.normal_stiffness, g.radius_eff), k_r, kRoundoff);
  const Real limit = 1.25e-3;
  const Real dt = 1e-4;
  const Real increment = k_r * 5.0 * dt;  // 1.7578e-5 N m per step: limit after 71 steps
  Vec<3> history = Vec<3>::Zero();
  for (int k = 1; k <= 100; ++k) {
    const RollingTorque<3> r = rolling_resistance<3>(p, g, v, load, history, dt);
    history = r.history;
    EXPECT_NEAR(r.torque_on_1.x(), 0.0, 1e-18);  // no torsion
    EXPECT_LT(r.torque_on_1.y(), 0.0);           // opposes the relative rolling
    if (k * increment < limit * (1 - 1e-9)) {
      EXPECT_FALSE(r.at_limit);
      expect_rel(r.torque_on_1.norm(), k * increment, 1e-10);
    } else if (k * increment > limit * (1 + 1e-9)) {
      EXPECT_TRUE(r.at_limit);
      expect_rel(r.torque_on_1.norm(), limit, kRoundoff);
    }
  }
  // Off by default: mu_r = 0 gives nothing.
  const RollingTorque<3> off =
      rolling_resistance<3>(RollingResistanceParams{}, g, v, load, Vec<3>::Zero(), dt);
  EXPECT_EQ(off.torque_on_1.norm(), 0.0);
  // 2D (scalar spin), with a dashpot: sticking torque = spring - C_r omega_r,
  // C_r = eta_r 2 sqrt(I_r k_r).
  const RollingResistanceParams damped{.friction = 0.1, .damping_ratio = 0.3};
  ContactGeometry<2> g2;
  g2.normal = Vec<2>(1, 0);
  g2.radius_eff = 1.25e-3;
  RelativeVelocity<2> v2;
  v2.spin = -5.0;
  const RollingLoad load2{.normal_force = 10.0, .normal_stiffness = 1e6, .inertia_eff = 2e-9};
  const RollingTorque<2> r2 = rolling_resistance<2>(damped, g2, v2, load2, 0.0, dt);
  const Real c_r = 0.3 * 2 * std::sqrt(2e-9 * k_r);
  expect_rel(r2.torque_on_1, increment + c_r * 5.0, kRoundoff);
  expect_rel(r2.history, increment, kRoundoff);
  expect_rel(rolling_inertia_eff(RollingBody{1.0, 2.0, 1.0}, RollingBody{1.0, 2.0, 1.0}), 1.5,
             kRoundoff);
}

// ------------------------------------------------------------------------------------------
// Parallel bond.

template <int D>
ContactGeometry<D> bond_geometry() {
  ContactGeometry<D> g;
  g.normal = Vec<D>::Unit(0);
  g.overlap = 0.0;
  g.radius_eff = 0.5e-3;
  g.arm1 = g.arm2 = 1e-3;
  return g;
}

/// Pulled apart at a constant rate, the bond's tensile stress grows by k_n v dt per step; it
/// must hold while sigma < sigma_c and break at the first step with sigma >= sigma_c.
template <int D>
void check_bond_tension() {
  const ParallelBondParams p{.normal_stiffness_pa_m = 1e12,
                             .shear_stiffness_pa_m = 0.5e12,
                             .tensile_strength_pa = 1e6,
                             .shear_strength_pa = 2e6};
  const ContactGeometry<D> g = bond_geometry<D>();
  RelativeVelocity<D> v;
  v.normal = 1e-3;  // separating
  const Real dt = 1.2345e-6;
  const Real increment = 1e12 * 1e-3 * dt;  // sigma per step [Pa]
  ParallelBondState<D> s = parallel_bond_state<D>(1e-3);
  const BondSection sec = bond_section<D>(1e-3);
  int broke_at = -1;
  for (int k = 1; k < 2000 && broke_at < 0; ++k) {
    const ParallelBondResult<D> r = parallel_bond<D>(p, g, v, s, dt);
    expect_rel(r.tensile_stress, k * increment, 1e-10);
    if (r.broken) {
      broke_at = k;
      EXPECT_EQ(r.force_on_1.norm(), 0.0);
      EXPECT_GE(r.tensile_stress, p.tensile_strength_pa);
      EXPECT_LT(r.tensile_stress - increment, p.tensile_strength_pa);
    } else {
      EXPECT_LT(r.tensile_stress, p.tensile_strength_pa);
      EXPECT_LT(r.force_on_1.dot(g.normal), 0.0);  // tension pulls body 1 toward body 2
      expect_rel(r.force_on_1.norm(), r.tensile_stress * sec.area, 1e-10);
    }
    s = r.state;
  }
  EXPECT_EQ(broke_at, static_cast<int>(std::ceil(1e6 / increment)));

  // Exactly at the strength it breaks (>=, paper eq. 21); a hair below it holds.
  ParallelBondState<D> at = parallel_bond_state<D>(1e-3);
  const RelativeVelocity<D> rest;
  at.normal_force = p.tensile_strength_pa * sec.area * (1 - 1e-9);
  EXPECT_FALSE((parallel_bond<D>(p, g, rest, at, dt).broken));
  at.normal_force = p.tensile_strength_pa * sec.area;
  const ParallelBondResult<D> exact = parallel_bond<D>(p, g, rest, at, dt);
  if (exact.tensile_stress >= p.tensile_strength_pa) {  // F/A*A/A may round either way
    EXPECT_TRUE(exact.broken);
  }
  at.normal_force = p.tensile_strength_pa * sec.area * (1 + 1e-9);
  EXPECT_TRUE((parallel_bond<D>(p, g, rest, at, dt).broken));
}

TEST(DemParallelBond, BreaksAtTensileStrength) {
  check_bond_tension<2>();
  check_bond_tension<3>();
}

TEST(DemParallelBond, SectionsBendingShearAndTorsion) {
  // 2D strip per metre: A = 2R, I = 2R^3/3; 3D disk: A = pi R^2, I = pi R^4/4, J = pi R^4/2.
  const Real r = 1e-3;
  expect_rel(bond_section<2>(r).area, 2e-3, kRoundoff);
  expect_rel(bond_section<2>(r).inertia, 2.0 / 3.0 * 1e-9, kRoundoff);
  expect_rel(bond_section<3>(r).area, kPi * 1e-6, kRoundoff);
  expect_rel(bond_section<3>(r).inertia, kPi * 1e-12 / 4, kRoundoff);
  expect_rel(bond_section<3>(r).polar_inertia, kPi * 1e-12 / 2, kRoundoff);
  expect_rel(parallel_bond_radius(BondRadiusRule::MinRadius, 0.8, 1e-3, 2e-3), 0.8e-3, kRoundoff);
  expect_rel(parallel_bond_radius(BondRadiusRule::MeanRadius, 0.8, 1e-3, 2e-3), 1.2e-3, kRoundoff);
  expect_rel(parallel_bond_radius(BondRadiusRule::EffectiveRadius, 0.8, 1e-3, 2e-3),
             0.8 * 2.0 / 3.0 * 1e-3, kRoundoff);

  const ParallelBondParams p{.normal_stiffness_pa_m = 1e12,
                             .shear_stiffness_pa_m = 0.5e12,
                             .tensile_strength_pa = 1e6,
                             .shear_strength_pa = 2e6};
  const Real dt = 1e-6;
  // 2D bending: one step of relative spin w gives M = -k_n I w dt, sigma = |M| R / I = k_n R w dt.
  {
    RelativeVelocity<2> v;
    v.spin = 0.5;
    const ParallelBondResult<2> b =
        parallel_bond<2>(p, bond_geometry<2>(), v, parallel_bond_state<2>(r), dt);
    expect_rel(b.state.bending_moment, -1e12 * bond_section<2>(r).inertia * 0.5 * dt, kRoundoff);
    expect_rel(b.tensile_stress, 1e12 * r * 0.5 * dt, kRoundoff);
    EXPECT_FALSE(b.broken);
    // Twice the rate of the strength in one step: sigma = 2 sigma_c, broken.
    v.spin = 2 * 1e6 / (1e12 * r * dt);
    EXPECT_TRUE((parallel_bond<2>(p, bond_geometry<2>(), v, parallel_bond_state<2>(r), dt).broken));
  }
  // Shear: tau = |F_s| / A = k_s |v_t| dt; 3D torsion adds |M_t| R / J = k_s R |w_t| dt.
  {
    RelativeVelocity<3> v;
    v.tangential = Vec<3>(0, 0.3, 0);
    v.spin = Vec<3>(0.7, 0, 0);  // about n = e_x: pure twist
    const ParallelBondResult<3> b =
        parallel_bond<3>(p, bond_geometry<3>(), v, parallel_bond_state<3>(r), dt);
    expect_rel(b.shear_stress, 0.5e12 * 0.3 * dt + 0.5e12 * r * 0.7 * dt, kRoundoff);
    EXPECT_EQ(b.tensile_stress, 0.0);
    EXPECT_EQ(b.state.bending_moment.norm(), 0.0);
    expect_rel(b.state.twisting_moment, -0.5e12 * bond_section<3>(r).polar_inertia * 0.7 * dt,
               kRoundoff);
    EXPECT_FALSE(b.broken);
    // Torques: twist moment on 1, opposite on 2; both feel the shear force's moment.
    const Vec<3> f_s = b.state.shear_force;
    const Vec<3> expect1 =
        b.state.twisting_moment * Vec<3>(1, 0, 0) + (-1e-3 * Vec<3>(1, 0, 0)).cross(f_s);
    EXPECT_NEAR((b.torque_on_1 - expect1).norm(), 0.0, kRoundoff * expect1.norm());
    // Enough shear in one step to reach tau_c: broken.
    v.tangential = Vec<3>(0, 2e6 / (0.5e12 * dt), 0);
    EXPECT_TRUE((parallel_bond<3>(p, bond_geometry<3>(), v, parallel_bond_state<3>(r), dt).broken));
  }
}

// ------------------------------------------------------------------------------------------
// Local damping and rate-dependent friction.

TEST(DemLocalDamping, OpposesVelocityPerComponent) {
  // F = (3, -2, 5), v = (-1, 0.5, 0), alpha = 0.7:
  //   F_d = -0.7 (|3| sign(-1), |-2| sign(0.5), |5| sign(0)) = (2.1, -1.4, 0),
  //   power = 0.7 (3*1 + 2*0.5 + 0) = 2.8 W.
  const LocalDamping<Vec<3>> d =
      local_damping_force<3>(kLocalDampingQuasiStatic, Vec<3>(3, -2, 5), Vec<3>(-1, 0.5, 0));
  EXPECT_NEAR((d.load - Vec<3>(2.1, -1.4, 0)).norm(), 0.0, kRoundoff);
  EXPECT_NEAR(d.dissipated_power, 2.8, kRoundoff);
  // 2D torque: M = -4, w = 2: M_d = -0.157 * 4 * 1; power = 0.157 * 4 * 2.
  const LocalDamping<Real> t2 = local_damping_torque<2>(kLocalDampingDynamic, -4.0, 2.0);
  EXPECT_NEAR(t2.load, -0.628, kRoundoff);
  EXPECT_NEAR(t2.dissipated_power, 1.256, kRoundoff);
  // 3D torque, and the 2D force.
  const LocalDamping<Vec<3>> t3 = local_damping_torque<3>(0.5, Vec<3>(1, 1, -1), Vec<3>(-3, 0, 2));
  EXPECT_NEAR((t3.load - Vec<3>(0.5, 0, -0.5)).norm(), 0.0, kRoundoff);
  const LocalDamping<Vec<2>> f2 = local_damping_force<2>(0.5, Vec<2>(-2, 4), Vec<2>(-1, -1));
  EXPECT_NEAR((f2.load - Vec<2>(1, 2)).norm(), 0.0, kRoundoff);
  // The paper's "0.157 = 5 % of critical": alpha = pi zeta.
  EXPECT_NEAR(kLocalDampingDynamic, kPi * 0.05, 1e-3);
}

TEST(DemRateDependentFriction, PaperValues) {
  // mu = tan 40 deg, beta = 0.05, reference 1/s:
  //   1/s -> 40 deg (mu unchanged); 10/s -> 40 * 1.05 = 42 deg, tan = 0.9004040442978399;
  //   1000/s -> 40 * 1.15 = 46 deg, tan = 1.0355303137905696.
  const Real deg = kPi / 180;
  const RateDependentFriction f = rate_dependent_friction(std::tan(40 * deg));
  EXPECT_EQ(dynamic_friction_coefficient(f, 1.0), f.static_friction);
  expect_rel(dynamic_friction_angle(f, 1.0), 40 * deg, kRoundoff);
  expect_rel(dynamic_friction_angle(f, 10.0), 42 * deg, kRoundoff);
  expect_rel(dynamic_friction_coefficient(f, 10.0), 0.9004040442978399, kRoundoff);
  expect_rel(dynamic_friction_angle(f, 1000.0), 46 * deg, kRoundoff);
  expect_rel(dynamic_friction_coefficient(f, 1000.0), 1.0355303137905696, kRoundoff);
  // Below the reference rate: no weakening (clamped), also at rest.
  EXPECT_EQ(dynamic_friction_coefficient(f, 0.1), f.static_friction);
  EXPECT_EQ(dynamic_friction_coefficient(f, 0.0), f.static_friction);
  // Finite for absurd rates (capped at 89 deg).
  EXPECT_LT(dynamic_friction_coefficient(f, 1e300), std::tan(89.0 * deg) * (1 + kRoundoff));
  // Strain rate estimate |v_n| / (R1 + R2): 2 m/s over 5 mm = 400 /s.
  expect_rel(contact_strain_rate(-2.0, 2.5e-3, 2.5e-3), 400.0, kRoundoff);
}

// ------------------------------------------------------------------------------------------
// Time scales, and the law types a pair loop is templated on.

TEST(DemTimeScales, RayleighStepAndHertzContactTime) {
  // /work/shared/peers/README.md: dt_R = 2.2227e-6 s for the paper's sand (5 digits printed).
  expect_rel(rayleigh_time_step(kSandRadius, kSandDensity, kSandShear, kSandPoisson), 2.2227e-6,
             3e-5);
  // 2 int_0^1 (1 - x^{5/2})^{-1/2} dx = (4/5) sqrt(pi) Gamma(2/5) / Gamma(9/10).
  expect_rel(kHertzContactTimeFactor, 0.8 * std::sqrt(kPi) * std::tgamma(0.4) / std::tgamma(0.9),
             1e-14);
  // Johnson's printed form 2.87 (m*^2 / (R* E*^2 v))^{1/5}; the exact constant is 2.8683,
  // so 1e-3 relative.
  const Real e_eff = 36.25e9;
  const Real r_eff = kSandRadius / 2;
  const Real m_eff = 0.5 * sphere_mass(kSandRadius);
  for (Real v : {0.1, 1.0, 10.0}) {
    expect_rel(hertz_contact_time(e_eff, r_eff, m_eff, v),
               2.87 * std::pow(m_eff * m_eff / (r_eff * e_eff * e_eff * v), 0.2), 1e-3);
  }
}

template <class Law, int D>
ContactForce<D> evaluate_law(const typename Law::Params& p, const ContactGeometry<D>& g) {
  return Law::template finish<D>(p, g, RelativeVelocity<D>{},
                                 Law::template prepare<D>(p, g, 1e-4, Vec<D>::Zero()), 1e-7);
}

// Absorbing wall (absorbing_wall.hpp): a grain r = 2 mm against a wall whose normal is +y,
// rho c_p = 3e5 and rho c_s = 1.5e5 kg/(m^2 s), held reaction F_0 = 2 N.
TEST(DemAbsorbingWall, HeldReactionPlusDashpots) {
  const AbsorbingWallParams p{.normal_impedance = 3e5, .tangential_impedance = 1.5e5};
  const Real r = 2e-3;
  EXPECT_DOUBLE_EQ(absorbing_wall_area<2>(r), 4e-3);   // 2r per metre of depth
  EXPECT_DOUBLE_EQ(absorbing_wall_area<3>(r), 16e-6);  // (2r)^2
  const Real area = absorbing_wall_area<3>(r);
  const Vec<3> n(0, 1, 0);
  // Moving into the wall at 0.1 m/s and along it at 0.2 m/s:
  // f_n = 2 + 3e5 * 16e-6 * 0.1 = 2.48 N; F_t = -1.5e5 * 16e-6 * 0.2 = -0.48 N.
  const auto in = absorbing_wall_force<3>(p, area, n, Vec<3>(0.2, -0.1, 0), 2.0);
  EXPECT_NEAR(in.force.x(), -0.48, 1e-12);
  EXPECT_NEAR(in.force.y(), 2.48, 1e-12);
  EXPECT_NEAR(in.force.z(), 0.0, 1e-15);
  // The reaction's work rate 2 * (-0.1); dissipated 0.48 * 0.1 + 0.48 * 0.2.
  EXPECT_NEAR(in.static_power, -0.2, 1e-12);
  EXPECT_NEAR(in.dissipated_power, 0.048 + 0.096, 1e-12);
  // Leaving at 1 m/s: 2 - 4.8 < 0, so the wall lets go (never pulls): f_n = 0; the held
  // reaction's power 2 W is then all dissipated by the dashpot's share.
  const auto out = absorbing_wall_force<3>(p, area, n, Vec<3>(0, 1, 0), 2.0);
  EXPECT_EQ(out.force.y(), 0.0);
  EXPECT_NEAR(out.static_power, 2.0, 1e-12);
  EXPECT_NEAR(out.dissipated_power, 2.0, 1e-12);
  EXPECT_NEAR(out.static_power - out.dissipated_power, out.force.dot(Vec<3>(0, 1, 0)), 1e-12);
  // 2D, at rest: the held reaction alone.
  const auto rest =
      absorbing_wall_force<2>(p, absorbing_wall_area<2>(r), Vec<2>(-1, 0), Vec<2>::Zero(), 0.5);
  EXPECT_DOUBLE_EQ(rest.force.x(), -0.5);
  EXPECT_DOUBLE_EQ(rest.dissipated_power, 0.0);
  // A grain no other grain pushes on (not in the bed): the normal dashpot and the held reaction
  // as before, no tangential dashpot (it would carry a loose grain's weight on the face).
  const auto loose = absorbing_wall_force<3>(p, area, n, Vec<3>(0.2, -0.1, 0), 2.0, false);
  EXPECT_EQ(loose.force.x(), 0.0);
  EXPECT_NEAR(loose.force.y(), 2.48, 1e-12);
  EXPECT_NEAR(loose.dissipated_power, 0.048, 1e-12);
}

TEST(DemLawTypes, SameSignatureForPairLoops) {
  ContactGeometry<3> g;
  g.normal = Vec<3>(0, 1, 0);
  g.overlap = 1e-6;
  g.radius_eff = 1e-3;
  // Linear: F = k_n delta; Hertz: (4/3) E* sqrt(R*) delta^{3/2}.
  expect_rel(
      evaluate_law<LinearSpring, 3>(linear_spring_params(1e6, 1e6, 1.0, 0.5), g).normal_force, 1.0,
      kRoundoff);
  expect_rel(
      evaluate_law<HertzMindlin, 3>(hertz_mindlin_params(sand(), sand(), 1.0, 0.5), g).normal_force,
      4.0 / 3.0 * 36.25e9 * std::sqrt(1e-3) * 1e-9, kRoundoff);
  static_assert(std::is_same_v<AngularVec<2>, Real>);
  static_assert(std::is_same_v<AngularVec<3>, Vec<3>>);
}

}  // namespace
}  // namespace crater::dem
