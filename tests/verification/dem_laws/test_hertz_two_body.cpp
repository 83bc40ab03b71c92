// Verification: head-on collisions integrated with the Hertz-Mindlin law (src/dem/laws/).
//
// References (computed by nobody here):
//   - Undamped Hertz impact, K. L. Johnson, "Contact Mechanics" (1985), §11.4:
//       δ_max = (15 m* v^2 / (16 E* \sqrt{R*}))^{2/5},
//       t_c   = 2.94 δ_max / v = 2.87 (m*^2 / (R* E*^2 v))^{1/5}.
//   - Damped Hertz (Tsuji form, LIGGGHTS `model hertz`): the restitution equals the e the damping
//     was built from, for every impact speed (D. Antypov, J. A. Elliott, EPL 94 (2011) 50004).
// The paper's sand (§III-C): R = 2.5 mm, \rho = 1920 kg/m^3, G = 29 GPa, \nu = 0.2.
//
// Both bodies are moved by velocity Verlet inside the test (the scheme of crater's time loop:
// half kick, drift, force at the new positions with the half-step velocity, half kick), with
// 20000 or more steps per contact (the restitution cases share one step size for all speeds);
// the contact starts at δ = 0 at t = 0 and its end is interpolated linearly where δ returns
// to 0. The restitution cases also print, for information, e at the step a production run
// would take (0.2 Δt_R, 20-60 steps per contact) and with the attractive end of the force cut
// off (LIGGGHTS `limitForce`); neither is asserted beyond "the cut-off raises e".
//
// Tolerances: 2 % on every quantity (the brief's requirement). What is expected inside it:
// t_c and δ_max to ~1e-6 (Verlet is second order; (π/20000)^2 ~ 2e-8), the restitution to
// ~1e-4 (the dashpot sees the half-step velocity, an O(Δt/t_c) error).
//
// 2D (disks): no closed form exists for the Hertz contact of two parallel cylinders (the approach
// depends logarithmically on the contact width and body size, Johnson ch. 4-5), and 2D DEM codes
// apply the sphere law to disks. The 2D case below runs the D = 2 instantiation of the same law
// on the same ODE, so it checks the 2D code path against the sphere closed form, not a disk
// contact theory.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <ostream>
#include <string>

#include "dem/laws/contact_geometry.hpp"
#include "dem/laws/hertz_mindlin.hpp"

namespace crater::dem {
namespace {

constexpr Real kPi = std::numbers::pi;
constexpr Real kRadius = 2.5e-3;   // m
constexpr Real kDensity = 1920.0;  // kg/m^3
constexpr Real kShear = 29e9;      // Pa
constexpr Real kPoisson = 0.2;     // -
constexpr Real kTolerance = 0.02;  // the brief's 2 %
constexpr int kStepsPerContact = 20000;

ElasticMaterial sand() {
  return ElasticMaterial{.youngs_modulus_pa = youngs_modulus_from_shear(kShear, kPoisson),
                         .poisson_ratio = kPoisson};
}

Real sphere_mass(Real r) {
  return kDensity * 4.0 / 3.0 * kPi * r * r * r;
}

struct Collision {
  Real contact_time = 0;  // s
  Real max_overlap = 0;   // m
  Real restitution = 0;   // rebound / approach normal speed
  int steps_in_contact = 0;
};

/// Two spheres (or a sphere and a fixed wall) approaching head-on along x at relative speed
/// `speed`, touching at t = 0; integrated until they separate.
template <int D>
Collision collide(const HertzMindlinParams& p, Real m1, Real r1, Real m2, Real r2, bool wall,
                  Real speed, Real dt) {
  const Vec<D> ex = Vec<D>::Unit(0);
  // Centre-of-mass frame for two spheres; the wall does not move.
  Vec<D> x1 = Vec<D>::Zero();
  Vec<D> v1 = (wall ? speed : speed * m2 / (m1 + m2)) * ex;
  Vec<D> x2 = (r1 + r2) * ex;  // a wall: its surface point, r2 ignored
  if (wall) x2 = r1 * ex;
  Vec<D> v2 = wall ? Vec<D>::Zero() : Vec<D>(-speed * m1 / (m1 + m2) * ex);
  const Real m_eff = wall ? m1 : effective_mass(m1, m2);
  Vec<D> force_on_1 = Vec<D>::Zero();
  Vec<D> history = Vec<D>::Zero();
  Collision out;
  Real t = 0;
  Real previous_overlap = 0;
  const int max_steps = 10 * kStepsPerContact;
  for (int k = 0; k < max_steps; ++k) {
    v1 += 0.5 * dt / m1 * force_on_1;
    x1 += dt * v1;
    if (!wall) {
      v2 -= 0.5 * dt / m2 * force_on_1;
      x2 += dt * v2;
    }
    t += dt;
    const ContactGeometry<D> g = wall ? sphere_wall_geometry<D>(x1, r1, Vec<D>(x2))
                                      : sphere_sphere_geometry<D>(x1, r1, x2, r2);
    if (g.touching()) {
      const RelativeVelocity<D> rv = relative_velocity<D>(g, BodyMotion<D>{v1, angular_zero<D>()},
                                                          BodyMotion<D>{v2, angular_zero<D>()});
      const ContactForce<D> c = hertz_mindlin<D>(p, g, rv, m_eff, history, dt);
      history = c.shear_history;
      force_on_1 = c.force_on_1;
      out.max_overlap = std::max(out.max_overlap, g.overlap);
      ++out.steps_in_contact;
    } else {
      force_on_1.setZero();
    }
    v1 += 0.5 * dt / m1 * force_on_1;
    if (!wall) v2 -= 0.5 * dt / m2 * force_on_1;
    if (previous_overlap > 0 && !g.touching()) {
      out.contact_time = t - dt * g.overlap / (g.overlap - previous_overlap);
      out.restitution = (wall ? -v1.x() : (v2 - v1).x()) / speed;
      return out;
    }
    previous_overlap = g.overlap;
  }
  ADD_FAILURE() << "no separation within " << max_steps << " steps";
  return out;
}

struct Case {
  std::string name;
  int dim;
  bool wall;
  Real speed;
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.name << ", v = " << c.speed << " m/s";
}

template <int D>
void check_undamped(const Case& c) {
  const ElasticMaterial rigid{.youngs_modulus_pa = std::numeric_limits<Real>::infinity(),
                              .poisson_ratio = 0.3};
  const HertzMindlinParams p = hertz_mindlin_params(sand(), c.wall ? rigid : sand(), 1.0, 0.84);
  const Real m = sphere_mass(kRadius);
  const Real m_eff = c.wall ? m : 0.5 * m;
  const Real r_eff = c.wall ? kRadius : 0.5 * kRadius;
  const Real e_eff = p.youngs_modulus_eff_pa;
  // Johnson §11.4, written out here rather than calling the header's helpers.
  const Real overlap_ref =
      std::pow(15.0 * m_eff * c.speed * c.speed / (16.0 * e_eff * std::sqrt(r_eff)), 0.4);
  const Real time_ref = 2.87 * std::pow(m_eff * m_eff / (r_eff * e_eff * e_eff * c.speed), 0.2);
  const Collision r =
      collide<D>(p, m, kRadius, m, kRadius, c.wall, c.speed, time_ref / kStepsPerContact);
  const Real overlap_err = r.max_overlap / overlap_ref - 1;
  const Real time_err = r.contact_time / time_ref - 1;
  // The exact constant 2 int_0^1 (1 - x^{5/2})^{-1/2} dx = 2.9433 in place of Johnson's rounded
  // 2.87 (which is 0.06 % high): isolates the integration error.
  const Real time_exact =
      0.8 * std::sqrt(kPi) * std::tgamma(0.4) / std::tgamma(0.9) * overlap_ref / c.speed;
  const Real time_exact_err = r.contact_time / time_exact - 1;
  std::printf(
      "[hertz %s] v = %g m/s: t_c = %.6e s (Johnson 2.87 form %.6e, err %+.2e; exact "
      "constant %.6e, err %+.2e), delta_max = %.6e m (ref %.6e, err %+.2e), e = %.8f, "
      "%d steps\n",
      c.name.c_str(), c.speed, r.contact_time, time_ref, time_err, time_exact, time_exact_err,
      r.max_overlap, overlap_ref, overlap_err, r.restitution, r.steps_in_contact);
  ::testing::Test::RecordProperty("contact_time_s", std::to_string(r.contact_time));
  ::testing::Test::RecordProperty("contact_time_rel_err", std::to_string(time_err));
  ::testing::Test::RecordProperty("max_overlap_m", std::to_string(r.max_overlap));
  ::testing::Test::RecordProperty("max_overlap_rel_err", std::to_string(overlap_err));
  EXPECT_LT(std::abs(overlap_err), kTolerance);
  EXPECT_LT(std::abs(time_err), kTolerance);
  EXPECT_LT(std::abs(time_exact_err), kTolerance);
  // Undamped: the rebound speed equals the approach speed (energy is conserved).
  EXPECT_NEAR(r.restitution, 1.0, kTolerance);
}

class HertzUndamped : public ::testing::TestWithParam<Case> {};

TEST_P(HertzUndamped, ContactTimeAndMaxOverlapMatchJohnson) {
  const Case& c = GetParam();
  if (c.dim == 2) {
    check_undamped<2>(c);
  } else {
    check_undamped<3>(c);
  }
}

INSTANTIATE_TEST_SUITE_P(SandSpheres, HertzUndamped,
                         ::testing::Values(Case{"sphere_sphere_3d", 3, false, 1.0},
                                           Case{"sphere_rigid_wall_3d", 3, true, 1.0},
                                           Case{"sphere_sphere_3d_v10", 3, false, 10.0},
                                           Case{"disk_disk_2d_sphere_law", 2, false, 1.0}),
                         [](const ::testing::TestParamInfo<Case>& case_info) {
                           return case_info.param.name;
                         });

// ------------------------------------------------------------------------------------------
// Restitution with the Tsuji-form dashpot.

struct RestitutionCase {
  Real e;
  Real speed;
};

void PrintTo(const RestitutionCase& c, std::ostream* os) {
  *os << "e = " << c.e << ", v = " << c.speed << " m/s";
}

class HertzRestitution : public ::testing::TestWithParam<RestitutionCase> {};

TEST_P(HertzRestitution, ReboundSpeedRatioIsE) {
  const RestitutionCase rc = GetParam();
  const HertzMindlinParams p = hertz_mindlin_params(sand(), sand(), rc.e, 0.84);
  const Real m = sphere_mass(kRadius);
  // One step size for all speeds (20000 steps in the shortest, 10 m/s, contact; 2.5x more at
  // 0.1 m/s), so a speed dependence of e could not hide in a step scaled with t_c.
  const Real dt =
      hertz_contact_time(p.youngs_modulus_eff_pa, 0.5 * kRadius, 0.5 * m, 10.0) / kStepsPerContact;
  const Collision r = collide<3>(p, m, kRadius, m, kRadius, false, rc.speed, dt);
  const Real err = r.restitution / rc.e - 1;

  // For information: the same collision at the step a production run would use,
  // dt = 0.2 dt_R = 4.445e-7 s (peers/README.md), and with the attractive force cut off.
  const Real dt_run = 0.2 * rayleigh_time_step(kRadius, kDensity, kShear, kPoisson);
  const Collision coarse = collide<3>(p, m, kRadius, m, kRadius, false, rc.speed, dt_run);
  HertzMindlinParams clamped = p;
  clamped.limit_attractive_force = true;
  const Collision cut = collide<3>(clamped, m, kRadius, m, kRadius, false, rc.speed, dt);

  std::printf(
      "[restitution] e = %.2f, v = %5.1f m/s: measured %.6f (err %+.2e, %d steps); "
      "at dt = 0.2 dt_R: %.4f (%d steps); with F_n >= 0: %.4f\n",
      rc.e, rc.speed, r.restitution, err, r.steps_in_contact, coarse.restitution,
      coarse.steps_in_contact, cut.restitution);
  RecordProperty("restitution", std::to_string(r.restitution));
  RecordProperty("restitution_rel_err", std::to_string(err));
  RecordProperty("restitution_at_production_dt", std::to_string(coarse.restitution));
  RecordProperty("restitution_clamped", std::to_string(cut.restitution));
  EXPECT_LT(std::abs(err), kTolerance);
  // Cutting the attractive end of the force off ends the contact early: less is dissipated.
  EXPECT_GT(cut.restitution, r.restitution);
}

INSTANTIATE_TEST_SUITE_P(Sand, HertzRestitution,
                         ::testing::Values(RestitutionCase{0.3, 0.1}, RestitutionCase{0.3, 1.0},
                                           RestitutionCase{0.3, 10.0}, RestitutionCase{0.5, 0.1},
                                           RestitutionCase{0.5, 1.0}, RestitutionCase{0.5, 10.0},
                                           RestitutionCase{0.9, 0.1}, RestitutionCase{0.9, 1.0},
                                           RestitutionCase{0.9, 10.0}),
                         [](const ::testing::TestParamInfo<RestitutionCase>& case_info) {
                           char name[64];
                           std::snprintf(name, sizeof name, "e%02d_v%g",
                                         static_cast<int>(std::lround(case_info.param.e * 10)),
                                         case_info.param.speed);
                           std::string s(name);
                           for (char& ch : s) {
                             if (ch == '.') ch = 'p';
                           }
                           return s;
                         });

}  // namespace
}  // namespace crater::dem
