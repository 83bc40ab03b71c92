// Unit tests of the SPH pair terms (src/sph/pair_terms.hpp): a pair's forces are equal and
// opposite, and the energy rates balance the work of those forces (the semi-discrete
// equations conserve momentum and kinetic + internal energy pair by pair).
#include <gtest/gtest.h>

#include "sph/kernels.hpp"
#include "sph/pair_terms.hpp"

namespace crater::sph {
namespace {

struct Particle {
  Vec<2> x, v;
  Real h, m, rho, p, c;
};

Centre<2> centre_of(const RateParams& c, const Particle& a) {
  Centre<2> me;
  me.x = a.x;
  me.v = a.v;
  me.h = a.h;
  me.rho = a.rho;
  me.c = a.c;
  me.p = a.p;
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
  Particle a{Vec<2>(0.0, 0.0), Vec<2>(3.0, -1.0), 0.013, 2.0, 1000.0, 2e5, 40.0};
  Particle b{Vec<2>(0.011, 0.004), Vec<2>(-2.0, 0.5), 0.012, 1.5, 950.0, -5e4, 35.0};
  RateParams c{.alpha = 1.0,
               .beta = 2.0,
               .viscosity_pa_s = 0.3,
               .eps_xsph = 0.5,
               .eps_tensile = 0.2,
               .spacing_m = 0.01};
};

TEST_F(PairTerms, MomentumIsConserved) {
  const PairSums<2> sa = sums(c, a, b), sb = sums(c, b, a);
  const Vec<2> total = a.m * sa.acc + b.m * sb.acc;
  EXPECT_GT((a.m * sa.acc).norm(), 0);
  EXPECT_LT(total.norm(), 1e-12 * (a.m * sa.acc).norm());
}

// The tensile correction is a momentum term only (Monaghan 2000 books no work for it): off here.
TEST_F(PairTerms, EnergyIsConserved) {
  c.eps_tensile = 0;
  const PairSums<2> sa = sums(c, a, b), sb = sums(c, b, a);
  // d/dt (kinetic + internal) = sum m (v . a + de/dt)
  const Real power = a.m * (a.v.dot(sa.acc) + sa.de) + b.m * (b.v.dot(sb.acc) + sb.de);
  const Real scale = std::abs(a.m * a.v.dot(sa.acc));
  EXPECT_GT(scale, 0);
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

}  // namespace
}  // namespace crater::sph
