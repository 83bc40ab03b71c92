// Unit tests of the SPH pair terms (src/sph/pair_terms.hpp): a pair's forces are equal and
// opposite, and the energy rates balance the work of those forces (the semi-discrete
// equations conserve momentum and kinetic + internal energy pair by pair), and the artificial
// conductivity (Price 2008) against its formula written out.
#include <gtest/gtest.h>
#include <cmath>

#include "sph/kernels.hpp"
#include "sph/pair_terms.hpp"

namespace crater::sph {
namespace {

struct Particle {
  Vec<2> x, v;
  Real h, m, rho, p, c, e;
};

Centre<2> centre_of(const RateParams& c, const Particle& a) {
  Centre<2> me;
  me.x = a.x;
  me.v = a.v;
  me.h = a.h;
  me.rho = a.rho;
  me.c = a.c;
  me.p = a.p;
  me.e = a.e;
  me.inv_rho = 1 / a.rho;
  me.r_tensile = artificial_pressure(c.eps_tensile, a.p, a.rho);
  return me;
}

Neighbour<2> neighbour_of(const Centre<2>& me, const Particle& b) {
  return {.rij = me.x - b.x,
          .m = b.m,
          .rho = b.rho,
          .p = b.p,
          .c = b.c,
          .e = b.e,
          .v = b.v,
          .v_visc = b.v,
          .wall = false};
}

PairSums<2> sums(const RateParams& c, const Particle& a, const Particle& b) {
  const Centre<2> me = centre_of(c, a);
  PairSums<2> s;
  const Neighbour<2> nb = neighbour_of(me, b);
  const PairKernel<2> k = pair_kernel<WendlandC2<2>>(nb.rij, a.h, b.h);
  if (k.within) gather_pair<WendlandC2<2>>(c, me, nb, k, s);
  return s;
}

class PairTerms : public ::testing::Test {
 protected:
  // Two approaching particles of different mass, density, pressure (one in tension) and
  // smoothing length; every term on.
  Particle a{Vec<2>(0.0, 0.0), Vec<2>(3.0, -1.0), 0.013, 2.0, 1000.0, 2e5, 40.0, 700.0};
  Particle b{Vec<2>(0.011, 0.004), Vec<2>(-2.0, 0.5), 0.012, 1.5, 950.0, -5e4, 35.0, 250.0};
  RateParams c{.alpha = 1.0,
               .beta = 2.0,
               .viscosity_pa_s = 0.3,
               .eps_xsph = 0.5,
               .eps_tensile = 0.2,
               .alpha_u = 1.0,
               .spacing_m = 0.01};
};

TEST_F(PairTerms, MomentumIsConserved) {
  const PairSums<2> sa = sums(c, a, b), sb = sums(c, b, a);
  const Vec<2> total = a.m * sa.acc + b.m * sb.acc;
  EXPECT_GT((a.m * sa.acc).norm(), 0);
  EXPECT_LT(total.norm(), 1e-12 * (a.m * sa.acc).norm());
}

// The tensile correction is a momentum term only (Monaghan 2000 books no work for it): off here.
// The conductivity is on: it only moves internal energy within the pair.
TEST_F(PairTerms, EnergyIsConserved) {
  c.eps_tensile = 0;
  const PairSums<2> sa = sums(c, a, b), sb = sums(c, b, a);
  // d/dt (kinetic + internal) = sum m (v . a + de/dt)
  const Real power = a.m * (a.v.dot(sa.acc) + sa.de) + b.m * (b.v.dot(sb.acc) + sb.de);
  const Real scale = std::abs(a.m * a.v.dot(sa.acc)) + std::abs(a.m * sa.de);
  EXPECT_GT(std::abs(a.m * a.v.dot(sa.acc)), 0);
  EXPECT_LT(std::abs(power), 1e-12 * scale);
}

TEST_F(PairTerms, ViscosityActsOnApproachOnly) {
  const Centre<2> me = centre_of(c, a);
  const Neighbour<2> nb = neighbour_of(me, b);
  const PairKernel<2> k = pair_kernel<WendlandC2<2>>(nb.rij, me.h, b.h);
  ASSERT_TRUE(k.within);
  const Approach<2> in = relative_motion(me, nb, k);
  EXPECT_LT(in.vdotr, 0);
  EXPECT_GT(monaghan_viscosity(c, me, nb, in), 0);
  Neighbour<2> away = nb;
  away.v = away.v_visc = Vec<2>(2 * a.v - b.v);  // the same speed, receding
  const Approach<2> out = relative_motion(me, away, k);
  EXPECT_GT(out.vdotr, 0);
  EXPECT_EQ(monaghan_viscosity(c, me, away, out), 0);
}

TEST_F(PairTerms, NothingBeyondTheSupport) {
  Particle far = b;
  far.x = Vec<2>(1.0, 0.0);
  const PairSums<2> s = sums(c, a, far);
  EXPECT_EQ(s.acc, Vec<2>::Zero());
  EXPECT_EQ(s.drho, 0);
  EXPECT_EQ(s.de, 0);
  EXPECT_EQ(s.mu_max, 0);
}

// Price (2008): de_i/dt = m_j alpha_u v_sig^u (e_i - e_j) / rhobar dW/dr(r, hbar),
// v_sig^u = sqrt(|p_i - p_j| / rhobar), rhobar = (rho_i + rho_j) / 2, hbar = (h_i + h_j) / 2:
// written out here with the kernel's radial derivative, not through grad_i W.
TEST_F(PairTerms, ConductivityHasPricesValue) {
  const Centre<2> me = centre_of(c, a);
  const Neighbour<2> nb = neighbour_of(me, b);
  const PairKernel<2> k = pair_kernel<WendlandC2<2>>(nb.rij, a.h, b.h);
  ASSERT_TRUE(k.within);
  const Real rhobar = 0.5 * (a.rho + b.rho);
  const Real vsig = std::sqrt(std::abs(a.p - b.p) / rhobar);
  const Real r = (a.x - b.x).norm();
  const Real dwdr = WendlandC2<2>::dw_dr(r, 0.5 * (a.h + b.h));
  const Real expect = b.m * c.alpha_u * vsig * (a.e - b.e) / rhobar * dwdr;
  const HeatFlux f = artificial_conductivity(c, me, nb, k);
  EXPECT_LT(dwdr, 0);
  EXPECT_LT(f.heat, 0);  // a is hotter (e 700 > 250 J/kg): it loses heat to b
  EXPECT_NEAR(f.heat, expect, 1e-13 * std::abs(expect));
  EXPECT_DOUBLE_EQ(f.vsig, c.alpha_u * vsig);
  // The gather adds it to de/dt and nothing else.
  RateParams off = c;
  off.alpha_u = 0;
  EXPECT_NEAR(sums(c, a, b).de - sums(off, a, b).de, expect, 1e-12 * std::abs(expect));
  EXPECT_EQ(sums(c, a, b).acc, sums(off, a, b).acc);
  EXPECT_EQ(sums(c, a, b).drho, sums(off, a, b).drho);
}

// The heat a gains is the heat b loses: m_a de_a/dt + m_b de_b/dt = 0 to round-off.
TEST_F(PairTerms, ConductivityIsAntisymmetric) {
  const Centre<2> ca = centre_of(c, a), cb = centre_of(c, b);
  const Neighbour<2> na = neighbour_of(cb, a), nb = neighbour_of(ca, b);
  const HeatFlux fa =
      artificial_conductivity(c, ca, nb, pair_kernel<WendlandC2<2>>(nb.rij, a.h, b.h));
  const HeatFlux fb =
      artificial_conductivity(c, cb, na, pair_kernel<WendlandC2<2>>(na.rij, b.h, a.h));
  EXPECT_GT(fb.heat, 0);
  EXPECT_LT(std::abs(a.m * fa.heat + b.m * fb.heat), 1e-14 * std::abs(a.m * fa.heat));
  EXPECT_EQ(fa.vsig, fb.vsig);
}

TEST_F(PairTerms, ConductivityVanishesForEqualEnergyOrAlphaZero) {
  Particle same = b;
  same.e = a.e;
  const Centre<2> me = centre_of(c, a);
  const Neighbour<2> nb = neighbour_of(me, same);
  const PairKernel<2> k = pair_kernel<WendlandC2<2>>(nb.rij, a.h, b.h);
  EXPECT_EQ(artificial_conductivity(c, me, nb, k).heat, 0.0);
  RateParams off = c;
  off.alpha_u = 0;
  const Neighbour<2> hot = neighbour_of(me, b);
  EXPECT_EQ(artificial_conductivity(off, me, hot, k).heat, 0.0);
  EXPECT_EQ(artificial_conductivity(off, me, hot, k).vsig, 0.0);
  // Equal pressures: no signal speed, no heat (the term acts at pressure jumps only).
  Particle level = b;
  level.p = a.p;
  EXPECT_EQ(artificial_conductivity(c, me, neighbour_of(me, level), k).heat, 0.0);
}

// A fixed wall particle cannot take heat: the wall is adiabatic.
TEST_F(PairTerms, ConductivitySkipsWallParticles) {
  const Centre<2> me = centre_of(c, a);
  Neighbour<2> wall = neighbour_of(me, b);
  wall.wall = true;
  const PairKernel<2> k = pair_kernel<WendlandC2<2>>(wall.rij, a.h, b.h);
  EXPECT_EQ(artificial_conductivity(c, me, wall, k).heat, 0.0);
}

}  // namespace
}  // namespace crater::sph
