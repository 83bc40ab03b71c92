// Unit tests of the DEM contact-law registry (src/dem/contact_laws.hpp) and of what each law
// answers the part (src/dem/laws/law_binding.hpp). Reference values are hand-computed (numbers
// in the comments); tolerances are rounding level unless a comment says otherwise.
#include <gtest/gtest.h>

#include <cmath>
#include <variant>

#include "dem/contact_laws.hpp"

namespace crater::dem {
namespace {

constexpr Real kRoundoff = 1e-12;  // relative

static_assert(PartContactLaw<HertzMindlin>);
static_assert(PartContactLaw<LinearSpring>);

void expect_rel(Real actual, Real expected, Real rel) {
  EXPECT_NEAR(actual, expected, rel * std::abs(expected)) << "expected " << expected;
}

// The paper's sand (§III-C): G = 29 GPa, nu = 0.2, mu = 0.84, e = 0.5; walls mu 0.5, e 0.3.
GranularMaterial sand() {
  return GranularMaterial{
      .shear_modulus_pa = 29e9, .poisson_ratio = 0.2, .friction = 0.84, .restitution = 0.5};
}
// dem::Settings state no defaults (the schema does): every field a law reads is set here.
Settings settings(ContactLawKind kind) {
  Settings s;
  s.contact = kind;
  s.rayleigh_fraction = 0.25;        // the schema's default
  s.stiffness_step_fraction = 0.17;  // likewise
  s.normal_stiffness_n_m = 1e5;
  s.shear_stiffness_n_m = 4e5;
  s.wall_friction = 0.5;
  s.wall_restitution = 0.3;
  return s;
}

TEST(DemContactLawRegistry, PicksTheLawOfTheSettings) {
  const ContactLaws hertz =
      ContactLawRegistry::make(settings(ContactLawKind::HertzMindlin), sand());
  ASSERT_TRUE(std::holds_alternative<LawPair<HertzMindlin>>(hertz));
  const ContactLaws linear =
      ContactLawRegistry::make(settings(ContactLawKind::LinearSpring), sand());
  ASSERT_TRUE(std::holds_alternative<LawPair<LinearSpring>>(linear));
}

TEST(DemContactLawRegistry, HertzMindlinPairOfGrainAndWall) {
  const auto laws = std::get<LawPair<HertzMindlin>>(
      ContactLawRegistry::make(settings(ContactLawKind::HertzMindlin), sand()));
  // E = 2 G (1 + nu) = 69.6 GPa; the same material on both sides: E* = E / (2 (1 - nu^2))
  // = 36.25 GPa, for the grains and for the walls (of the grain's material).
  expect_rel(laws.grain.youngs_modulus_eff_pa, 36.25e9, kRoundoff);
  expect_rel(laws.wall.youngs_modulus_eff_pa, 36.25e9, kRoundoff);
  EXPECT_EQ(laws.grain.friction, 0.84);
  EXPECT_EQ(laws.wall.friction, 0.5);
  // zeta = -ln e / sqrt(pi^2 + ln^2 e): e = 0.5 -> 0.215454, e = 0.3 -> 0.357857
  expect_rel(laws.grain.damping_ratio, 0.2154537619662468, 1e-12);
  expect_rel(laws.wall.damping_ratio, 0.3578571305033167, 1e-12);
}

TEST(DemContactLawRegistry, LinearSpringPairOfGrainAndWall) {
  const auto laws = std::get<LawPair<LinearSpring>>(
      ContactLawRegistry::make(settings(ContactLawKind::LinearSpring), sand()));
  EXPECT_EQ(laws.grain.normal_stiffness_n_m, 1e5);
  EXPECT_EQ(laws.wall.shear_stiffness_n_m, 4e5);
  EXPECT_EQ(laws.grain.friction, 0.84);
  EXPECT_EQ(laws.wall.friction, 0.5);
  expect_rel(laws.wall.damping_ratio, 0.3578571305033167, 1e-12);
}

TEST(DemContactLawRegistry, StableStepAnswers) {
  const Settings hertz = settings(ContactLawKind::HertzMindlin);
  const GranularMaterial grain = sand();
  // Rayleigh step of R = 2.5 mm, rho = 1920, G = 29 GPa, nu = 0.2: 2.2227e-6 s
  // (hertz_mindlin.hpp), times rayleigh_fraction 0.25; no spring for sqrt(m/k).
  const LawStep h = HertzMindlin::part_step(
      LawStepQuery{.dem = hertz, .grain = grain, .radius_min_m = 2.5e-3, .density_kg_m3 = 1920});
  expect_rel(h.dt_s, 0.25 * 2.2227e-6, 1e-4);  // the header's figure has 5 digits
  EXPECT_EQ(h.stiffness_n_m, 0.0);
  EXPECT_FALSE(h.reason.empty());
  // The linear spring: no step of its own, its stiffer spring max(k_n, k_s) = 4e5 N/m.
  const Settings linear = settings(ContactLawKind::LinearSpring);
  const LawStep l = LinearSpring::part_step(
      LawStepQuery{.dem = linear, .grain = grain, .radius_min_m = 2.5e-3, .density_kg_m3 = 1920});
  EXPECT_TRUE(std::isinf(l.dt_s));
  EXPECT_EQ(l.stiffness_n_m, 4e5);
}

TEST(DemContactLawRegistry, RowsOfSpheresAndWaveSpeed) {
  Settings hertz = settings(ContactLawKind::HertzMindlin);
  EXPECT_FALSE(HertzMindlin::row_of_spheres(hertz));
  hertz.hertz_row_of_spheres = true;
  EXPECT_TRUE(HertzMindlin::row_of_spheres(hertz));
  EXPECT_FALSE(LinearSpring::row_of_spheres(hertz));
  // A chain of grains r = 5 mm, m = 1 g on springs k_n = 1e5 N/m: c_p = 2 r sqrt(k_n / m)
  // = 0.01 x 1e4 = 100 m/s. Hertz-Mindlin has no estimate (the scenario gives c_p).
  const MeanGrain mean{.radius_m = 5e-3, .mass_kg = 1e-3};
  expect_rel(LinearSpring::p_wave_speed(settings(ContactLawKind::LinearSpring), mean).value(),
             100.0, kRoundoff);
  EXPECT_FALSE(HertzMindlin::p_wave_speed(hertz, mean).has_value());
}

}  // namespace
}  // namespace crater::dem
