// Verification: one Hex8 element of Holmquist-Johnson-Cook concrete (the 48 MPa set of [HJC93])
// through the FEM element loop (src/fem/explicit_solid.cpp: the law as a StrengthParams
// alternative, its per-element state mu_max, mu_p and damage in the mesh) in uniaxial strain:
// load through the elastic region and into compaction, unload, reload into the fully dense
// region, unload on the dense curve. Then erosion at full damage, on and off.
//
// Driver: a unit cube (node 0 at the origin) moved by v_z = r z / (1 - r dt), v_x = v_y = 0, so
// that L_zz = r exactly on the end-of-step configuration (the lateral faces stay put): the
// element is homogeneous and the volumetric strain is \mu = 1/l_z - 1, l_z the cube's height.
// Each step is compute_internal_forces on the moved nodes (inertia plays no part).
//
// References (written out below independently of the library, from the papers):
//   [HJC93] T. J. Holmquist, G. R. Johnson, W. H. Cook, Proc. 14th Int. Symp. Ballistics (1993)
//           591-600: the EOS (Fig. 3: elastic K_e = P_c/mu_c; crush line from (mu_c, P_c) to
//           (mu_pl, P_l); unloading in between with (1 - F) K_e + F K_1, F = (mu_max - mu_c) /
//           (mu_pl - mu_c); fully dense K_1 x + K_2 x^2 + K_3 x^3, x = (mu - mu_l)/(1 + mu_l)),
//           the strength sigma* = [A (1 - D) + B P*^N] (1 + C ln rate*) <= S_max, the damage
//           D += (d eps_p + d mu_p) / max(EF_min, D_1 (P* + T*)^D_2).
//   The uniaxial-strain deviator: with d e = d eps (-1/3, -1/3, 2/3) the deviator stays
//   s = s_zz (-1/2, -1/2, 1), q = 3/2 |s_zz|, and the elastic trial is s_zz + (4/3) G d eps;
//   radial return to sigma_y, d eps_p = (q_tr - sigma_y) / (3G).
// mu_pl (where the dense curve reaches P_l) is solved here by Newton's method (the library
// bisects). Tolerance: 1e-6 relative (the brief; what is expected is round-off, ~1e-12).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fem/element_geometry.hpp"
#include "fem/explicit_solid.hpp"

namespace crater::fem {
namespace {

// [HJC93]'s 48 MPa concrete, typed again (SI).
constexpr Real kRho0 = 2440, kG = 14.86e9, kA = 0.79, kB = 1.60, kC = 0.007, kN = 0.61;
constexpr Real kFc = 48e6, kT = 4e6, kSmax = 7.0, kEps0 = 1.0, kEfMin = 0.01, kD1 = 0.04, kD2 = 1.0;
constexpr Real kPc = 16e6, kMuC = 0.001, kK1 = 85e9, kK2 = -171e9, kK3 = 208e9, kPl = 800e6,
               kMuL = 0.1;

/// x_l with K_1 x + K_2 x^2 + K_3 x^3 = P_l, by Newton from P_l / K_1.
Real dense_lock_strain() {
  Real x = kPl / kK1;
  for (int it = 0; it < 100; ++it) {
    const Real f = kK1 * x + kK2 * x * x + kK3 * x * x * x - kPl;
    const Real df = kK1 + 2 * kK2 * x + 3 * kK3 * x * x;
    const Real step = f / df;
    x -= step;
    if (std::abs(step) < 1e-16 * x) break;
  }
  return x;
}

/// The independent material point of the header.
struct Reference {
  Real mu_pl = kMuL + (1 + kMuL) * dense_lock_strain();
  Real k_e = kPc / kMuC;
  Real mu_max = 0, mu_p = 0, damage = 0, s_zz = 0, eps_p = 0, pressure = 0;

  Real dense(Real mu) const {
    const Real x = (mu - kMuL) / (1 + kMuL);
    return x < 0 ? kK1 * x : kK1 * x + kK2 * x * x + kK3 * x * x * x;
  }
  Real loading(Real mu) const {
    if (mu <= kMuC) return k_e * mu;
    if (mu < mu_pl) return kPc + (kPl - kPc) * (mu - kMuC) / (mu_pl - kMuC);
    return dense(mu);
  }
  Real unloading_modulus(Real peak) const {
    const Real f = std::clamp((peak - kMuC) / (mu_pl - kMuC), 0.0, 1.0);
    return (1 - f) * k_e + f * kK1;
  }
  Real eos(Real mu) const {
    const Real peak = std::max(mu, mu_max);
    Real p;
    if (peak <= kMuC || mu >= peak) {
      p = loading(mu);
    } else if (peak < mu_pl) {
      p = loading(peak) - unloading_modulus(peak) * (peak - mu);
    } else {
      p = dense(mu);
    }
    return std::max(p, -kT * (1 - damage));
  }
  Real plastic_volumetric(Real peak) const {
    if (peak <= kMuC) return 0;
    const Real m = std::min(peak, mu_pl);
    return m - loading(m) / unloading_modulus(m);
  }

  /// One step: the cube's new height l_z, axial strain increment d_eps, rate r [1/s].
  void step(Real l_z, Real d_eps, Real r) {
    const Real mu = 1 / l_z - 1;
    pressure = eos(mu);
    mu_max = std::max(mu_max, mu);
    const Real mu_p_new = plastic_volumetric(mu_max);
    const Real d_mu_p = std::max(0.0, mu_p_new - mu_p);
    mu_p = std::max(mu_p, mu_p_new);
    const Real s_trial = s_zz + 4.0 / 3.0 * kG * d_eps;
    const Real q_trial = 1.5 * std::abs(s_trial);
    const Real rate = 2.0 / 3.0 * std::abs(r);  // sqrt(2/3 de:de) / dt
    const Real rate_factor = rate / kEps0 > 1 ? 1 + kC * std::log(rate / kEps0) : 1.0;
    const Real p_star = pressure / kFc;
    const Real intact = 1 - damage;
    const Real strength = p_star >= 0 ? kA * intact + kB * std::pow(p_star, kN)
                                      : std::max(0.0, kA * (1 + pressure / kT) * intact);
    const Real sigma_y = kFc * std::min(kSmax, strength * rate_factor);
    s_zz = s_trial;
    Real d_eps_p = 0;
    if (q_trial > sigma_y) {
      s_zz = s_trial * sigma_y / q_trial;
      d_eps_p = (q_trial - sigma_y) / (3 * kG);
    }
    eps_p += d_eps_p;
    const Real sum = (pressure + kT) / kFc;
    const Real eps_f = std::max(kEfMin, sum > 0 ? kD1 * std::pow(sum, kD2) : 0.0);
    const Real strain = d_eps_p + d_mu_p;
    if (strain > 0) damage = std::min(1.0, damage + strain / eps_f);
  }
};

SolidMaterial concrete(bool erode_at_full_damage) {
  SolidMaterial material;
  material.strength =
      materials::holmquist_johnson_cook_law(materials::holmquist_johnson_cook_48mpa_concrete());
  material.density_kg_m3 = kRho0;
  material.bulk_viscosity = {.quadratic = 0, .linear = 0};
  material.erode_at_full_damage = erode_at_full_damage;
  return material;
}

/// The cube and the uniaxial-strain driver of the header.
class UniaxialStrain {
 public:
  explicit UniaxialStrain(const SolidMaterial& material) : material_(material) {
    StructuredMeshSpec<3> spec;
    spec.cells = {1, 1, 1};
    mesh_ = structured_mesh<3>(spec);
    initialise<3>(mesh_, material_);
  }
  /// One step at axial rate r [1/s] (r < 0 compresses); returns the new height l_z.
  Real step(Real r, Real dt) {
    for (std::size_t i = 0; i < mesh_.position.size(); ++i) {
      mesh_.velocity[i] = Vec<3>(0, 0, r * mesh_.position[i][2] / (1 - r * dt));
      mesh_.position[i] += dt * mesh_.velocity[i];
    }
    report_ = compute_internal_forces<3>(mesh_, material_, dt);
    height_ /= 1 - r * dt;
    return height_;
  }
  const ExplicitMesh<3>& mesh() const { return mesh_; }
  const ForceReport& report() const { return report_; }

 private:
  SolidMaterial material_;
  ExplicitMesh<3> mesh_;
  ForceReport report_;
  Real height_ = 1;
};

Real relative(Real a, Real b) {
  return std::abs(a - b) / std::max(std::abs(b), Real(1e-300));
}

TEST(FemHolmquistJohnsonCook, UniaxialStrainLoadUnloadFollowsEosAndStrength) {
  UniaxialStrain cube(concrete(false));
  Reference ref;
  const Real rate = 1.0;  // |r| [1/s]: deviatoric rate 2/3 /s, below eps0 (no rate effect)
  const Real dt = 1e-4;   // axial strain 1e-4 per step
  struct Leg {
    Real target_mu;
    const char* what;
  };
  // Targets: region I (mu_c = 0.001), compaction, unloading in region II, reload through the
  // rest of the crush line into the fully dense region (mu_pl = 0.1106), unload on the dense
  // curve.
  const Leg legs[] = {{0.0008, "elastic"},
                      {0.05, "compaction"},
                      {0.045, "unload (II)"},
                      {0.15, "reload into dense"},
                      {0.14, "unload (III)"}};
  Real worst_p = 0, worst_axial = 0, worst_state = 0, mu = 0;
  int steps = 0;
  for (const Leg& leg : legs) {
    const Real r = leg.target_mu > mu ? -rate : rate;
    Real worst_leg = 0;
    while ((r < 0 && mu < leg.target_mu) || (r > 0 && mu > leg.target_mu)) {
      const Real l_z = cube.step(r, dt);
      ref.step(l_z, r * dt, r);
      mu = 1 / l_z - 1;
      ++steps;
      const materials::Mat3& s = cube.mesh().stress[0];
      const Real p = -s.trace() / 3;
      const Real axial = -ref.pressure + ref.s_zz;
      worst_leg = std::max(worst_leg, relative(p, ref.pressure));
      worst_axial = std::max(worst_axial, relative(s(2, 2), axial));
      // The lateral stresses and the state carried per element.
      EXPECT_LT(relative(s(0, 0), -ref.pressure - ref.s_zz / 2), 1e-6) << leg.what;
      worst_state = std::max({worst_state, relative(cube.mesh().mu_max[0], ref.mu_max),
                              std::abs(cube.mesh().plastic_volumetric_strain[0] - ref.mu_p),
                              std::abs(cube.mesh().damage[0] - ref.damage),
                              std::abs(cube.mesh().plastic_strain[0] - ref.eps_p)});
    }
    std::printf(
        "%-18s to mu = %.4f: p = %8.2f MPa, sigma_zz = %8.2f MPa, D = %.4f, "
        "mu_p = %.5f, max |p/p_ref - 1| = %.1e\n",
        leg.what, mu, ref.pressure / 1e6, cube.mesh().stress[0](2, 2) / 1e6, ref.damage, ref.mu_p,
        worst_leg);
    worst_p = std::max(worst_p, worst_leg);
  }
  std::printf("%d steps; max |p/p_ref - 1| = %.2e, |sigma_zz/ref - 1| = %.2e, state %.2e\n", steps,
              worst_p, worst_axial, worst_state);
  EXPECT_LT(worst_p, 1e-6);
  EXPECT_LT(worst_axial, 1e-6);
  EXPECT_LT(worst_state, 1e-6);
  // The path did reach every region and never failed the element.
  EXPECT_GT(ref.mu_max, ref.mu_pl);
  EXPECT_GT(ref.mu_p, 0);
  EXPECT_GT(ref.eps_p, 0);
  EXPECT_EQ(cube.mesh().eroded[0], 0);
}

TEST(FemHolmquistJohnsonCook, StableStepCoversTheStiffestSlope) {
  // The element's step L_e / c (no bulk viscosity here) must use a wave speed at least that of
  // the EOS slope the element is on, c^2 = ((1 + mu) dp/dmu + 4G/3) / rho (dp/drho =
  // (dp/dmu) / rho_0): along a load into the dense region and an unload, c = L_e / step is
  // compared with the slope of each step (the secant of the reference's p(mu)).
  UniaxialStrain cube(concrete(false));
  Reference ref;
  Real mu = 0, worst = 0;
  const Real dt = 1e-4;
  for (int k = 0; k < 2000; ++k) {
    const Real r = k < 1500 ? -1.0 : 1.0;  // to mu = e^0.15 - 1 = 0.16, then back
    const Real mu_before = mu;
    const Real p_before = ref.pressure;
    const Real l_z = cube.step(r, dt);
    ref.step(l_z, r * dt, r);
    mu = 1 / l_z - 1;
    const Real slope = std::abs((ref.pressure - p_before) / (mu - mu_before));
    const Real rho = kRho0 * (1 + mu);
    const Real c_slope = std::sqrt(((1 + mu) * slope + 4.0 / 3.0 * kG) / rho);
    const UniformStrainGradients<3> g =
        uniform_strain_gradients<3>(cube.mesh().element_positions(0));
    const Real c_used = characteristic_length<3>(g) / cube.report().stable_dt_s;
    worst = std::max(worst, c_slope / c_used);
  }
  std::printf("max c_slope / c_used = %.4f (mu reached %.3f)\n", worst, ref.mu_max);
  EXPECT_GT(ref.mu_max, ref.mu_pl);
  EXPECT_LE(worst, 1 + 1e-9);
}

TEST(FemHolmquistJohnsonCook, ErodesAtFullDamageOnlyWhenAsked) {
  // Uniaxial strain in tension: the pressure reaches the cutoff -T (1 - D), where the strength
  // A (1 + P*/T*) (1 - D) vanishes, so the deviatoric strain is all plastic and D grows at
  // d eps_p / EF_min until it reaches 1.
  for (const bool erode : {false, true}) {
    UniaxialStrain cube(concrete(erode));
    int reached = -1;
    for (int k = 0; k < 2000 && reached < 0; ++k) {
      const Real d_before = cube.mesh().damage[0];
      cube.step(1.0, 1e-4);
      EXPECT_EQ(cube.mesh().eroded[0] != 0, erode && cube.mesh().damage[0] >= 1)
          << "step " << k << ", D " << d_before << " -> " << cube.mesh().damage[0];
      if (cube.mesh().damage[0] >= 1) reached = k;
    }
    ASSERT_GE(reached, 0) << "D never reached 1";
    EXPECT_EQ(cube.report().newly_eroded, erode ? 1 : 0);
    if (!erode) {
      // It stays, carrying no tension (cutoff -T (1 - D) = 0) and no shear.
      for (int k = 0; k < 10; ++k)
        cube.step(1.0, 1e-4);
      EXPECT_EQ(cube.mesh().eroded[0], 0);
      EXPECT_NEAR(cube.mesh().stress[0].norm(), 0, 1e-6);
    }
  }
}

}  // namespace
}  // namespace crater::fem
