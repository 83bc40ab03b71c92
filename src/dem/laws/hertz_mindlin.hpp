// Hertz-Mindlin contact law with viscous damping and Coulomb friction: the default contact of
// the paper's sand (§III-C), as LIGGGHTS `pair gran model hertz tangential history` defines it.
//
// Normal (Hertz [H1882]; [J85] §4.2), with the tangent stiffness S_n and the [TTI92]
// dashpot \gamma_n (viscous_damping.hpp):
//   F_n^el = (4/3) E* \sqrt{R*} δ^{3/2}                       [N]
//   S_n    = dF_n^el/dδ = 2 E* \sqrt{R* δ}                     [N/m]
//   F_n    = F_n^el - \gamma_n v_n,   \gamma_n = 2 \sqrt{5/6} \zeta \sqrt{S_n m*}
// Tangential (Mindlin no-slip [M49], incremental history spring, tangential_history.hpp):
//   k_t = S_t = 8 G* \sqrt{R* δ}                               [N/m]
//   F_t = -k_t \xi - \gamma_t v_t,   \gamma_t = 2 \sqrt{5/6} \zeta \sqrt{S_t m*},
//   |F_t| <= \mu max(F_n, 0)   (tangential_history.hpp)
// with \zeta = -\ln e / \sqrt{\ln^2 e + \pi^2} (LIGGGHTS: \beta = -\zeta). E*, G*, R*, m* as
// contact_geometry.hpp defines them. The normal elastic energy is
//   U_n = \int_0^δ F_n^el = (8/15) E* \sqrt{R*} δ^{5/2} = (2/5) F_n^el δ   [J].
//
// Restitution: with the contact ending at δ = 0 (F_n may turn slightly attractive at the very
// end, LIGGGHTS' default) the head-on restitution is exactly e at any impact speed [AE11]
// (tests/verification/dem_laws measures it). With limit_attractive_force (F_n >= 0) the bodies
// separate earlier and the restitution is higher than e (about 0.40 for e = 0.3, 0.55 for 0.5).
//
// 2D: disks use the same law (as LAMMPS and LIGGGHTS with `dimension 2` do). There is no
// closed form for the Hertz contact of parallel cylinders (the approach depends
// logarithmically on the contact width and on the body size; [J85], line contact of parallel
// cylinders), so there is no 2D-specific law to use instead. Note the units: the sphere law
// gives a force in N; a 2D part whose masses are per metre of depth must say how it reads it.
//
// References
//   [H1882] H. Hertz, "Über die Berührung fester elastischer Körper", J. reine angew. Math. 92
//           (1882) 156-171.
//   [J85]   K. L. Johnson, "Contact Mechanics", Cambridge University Press (1985), §4.2, §11.4.
//   [M49]   R. D. Mindlin, "Compliance of elastic bodies in contact", J. Appl. Mech. 16 (1949)
//           259-268.
//   [TTI92] Y. Tsuji, T. Tanaka, T. Ishida, Powder Technol. 71 (1992) 239-250.
//   [AE11]  D. Antypov, J. A. Elliott, EPL 94 (2011) 50004.
//   [LXT05] Y. Li, Y. Xu, C. Thornton, "A comparison of discrete element simulations and
//           experiments for 'sandpiles' composed of spherical particles", Powder Technol. 160
//           (2005) 219-228 (the Rayleigh time step).
//   [LIGGGHTS] LIGGGHTS-PUBLIC 3.8, src/normal_model_hertz.h, src/tangential_model_history.h.
#pragma once

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "core/types.hpp"
#include "dem/laws/contact_force.hpp"
#include "dem/laws/contact_geometry.hpp"
#include "dem/laws/law_binding.hpp"
#include "dem/laws/tangential_history.hpp"
#include "dem/laws/viscous_damping.hpp"

namespace crater::dem {

/// Parameters of one material pair. Build with hertz_mindlin_params().
struct HertzMindlinParams {
  Real youngs_modulus_eff_pa = 0;       // E* [Pa]
  Real shear_modulus_eff_pa = 0;        // G* [Pa]
  Real damping_ratio = 0;               // \zeta from the restitution e [-]
  Real friction = 0;                    // \mu [-]
  bool tangential_damping = true;       // \gamma_t on (LIGGGHTS `tangential_damping on`)
  bool limit_attractive_force = false;  // clamp F_n >= 0 (LIGGGHTS `limitForce`, off)
  // Derived by hertz_mindlin_params (so that the pair loop does not divide and root them):
  Real stiffness_ratio = 0;       // S_t / S_n = 4 G* / E* [-]
  Real sqrt_stiffness_ratio = 0;  // \sqrt{S_t / S_n} = \gamma_t / \gamma_n [-]
};

/// Parameters for grains of materials a and b (a wall: its material, E = inf if rigid),
/// restitution e in (0, 1] and friction coefficient \mu.
inline HertzMindlinParams hertz_mindlin_params(const ElasticMaterial& a, const ElasticMaterial& b,
                                               Real restitution, Real friction) {
  HertzMindlinParams p;
  p.youngs_modulus_eff_pa = effective_youngs_modulus(a, b);
  p.shear_modulus_eff_pa = effective_shear_modulus(a, b);
  p.damping_ratio = damping_ratio_from_restitution(restitution);
  p.friction = friction;
  p.stiffness_ratio = Real(4) * p.shear_modulus_eff_pa / p.youngs_modulus_eff_pa;
  p.sqrt_stiffness_ratio = std::sqrt(p.stiffness_ratio);
  return p;
}

/// The Hertz spring alone at overlap δ [m] (δ <= 0: no force): F_n^el, S_n and U_n.
inline NormalForce hertz_normal_spring(Real youngs_modulus_eff, Real radius_eff, Real overlap) {
  NormalForce out;
  const Real delta = std::max(overlap, Real(0));
  const Real sqrt_rd = std::sqrt(radius_eff * delta);
  out.elastic_force = Real(4) / Real(3) * youngs_modulus_eff * sqrt_rd * delta;
  out.force = out.elastic_force;
  out.stiffness = Real(2) * youngs_modulus_eff * sqrt_rd;
  out.elastic_energy = Real(0.4) * out.elastic_force * delta;
  return out;
}

/// The law as a type, for a pair loop templated on it (contact_force.hpp), and what a DEM part
/// asks of it (law_binding.hpp; part_laws and part_step are defined at the end of this file).
struct HertzMindlin {
  using Params = HertzMindlinParams;

  /// The law's roots and divisions (contact_force.hpp, ContactPrep): the Hertz spring and both
  /// dashpot coefficients at the pair's overlap, mass_eff m* [kg], and the shear history \xi of
  /// the previous step [m] (zero for a new contact) carried into the current tangent plane.
  template <int D>
  [[gnu::always_inline]] static ContactPrep<D> prepare(const Params& p, const ContactGeometry<D>& g,
                                                       Real mass_eff, const Vec<D>& shear_history) {
    ContactPrep<D> out;
    out.spring = hertz_normal_spring(p.youngs_modulus_eff_pa, g.radius_eff, g.overlap);
    out.normal_damping = tsuji_dashpot_coefficient(p.damping_ratio, out.spring.stiffness, mass_eff);
    // S_t = (4 G*/E*) S_n, and so \gamma_t = \sqrt{4 G*/E*} \gamma_n.
    out.tangential_damping =
        p.tangential_damping ? p.sqrt_stiffness_ratio * out.normal_damping : Real(0);
    out.carried_history = rotate_into_tangent_plane(shear_history, g.normal);
    return out;
  }
  /// The force on a touching pair from its prepared part, velocities v, dt [s].
  template <int D>
  [[gnu::always_inline]] static ContactForce<D> finish(const Params& p, const ContactGeometry<D>& g,
                                                       const RelativeVelocity<D>& v,
                                                       const ContactPrep<D>& part, Real dt) {
    // S_t = 8 G* sqrt(R* δ) = (4 G*/E*) S_n.
    return finish_spring_dashpot<D>(g, v, part, p.stiffness_ratio * part.spring.stiffness,
                                    p.friction, p.limit_attractive_force, dt);
  }

  static LawPair<HertzMindlin> part_laws(const Settings& dem, const GranularMaterial& grain);
  static bool row_of_spheres(const Settings& dem) { return dem.hertz_row_of_spheres; }
  static LawStep part_step(const LawStepQuery& query);
  static std::optional<Real> p_wave_speed(const Settings& /*dem*/, const MeanGrain& /*mean*/) {
    return std::nullopt;  // none: the scenario gives absorbing walls' P-wave speed
  }
};

/// Hertz-Mindlin force on a touching pair (see the file comment). mass_eff m* [kg],
/// shear_history \xi of the previous step [m] (zero for a new contact), dt [s].
template <int D>
[[gnu::always_inline]] inline ContactForce<D> hertz_mindlin(const HertzMindlinParams& p,
                                                            const ContactGeometry<D>& g,
                                                            const RelativeVelocity<D>& v,
                                                            Real mass_eff,
                                                            const Vec<D>& shear_history, Real dt) {
  return law_force<HertzMindlin, D>(p, g, v, mass_eff, shear_history, dt);
}

// ---------------------------------------------------------------------------------------------
// Time scales.

/// Rayleigh critical time step of a Hertzian packing ([LXT05]; Thornton's estimate):
/// the time a Rayleigh wave takes to cross half a grain,
///   \Delta t_R = \pi R \sqrt{\rho / G} / (0.1631 \nu + 0.8766)   [s],
/// (0.1631 \nu + 0.8766) \sqrt{G/\rho} approximating the Rayleigh wave speed. R [m] is the
/// smallest grain radius, \rho [kg/m^3], G [Pa]. DEM codes run at 10-30 % of it. The paper's
/// sand (R = 2.5 mm, \rho = 1920, G = 29 GPa, \nu = 0.2): 2.2227e-6 s.
inline Real rayleigh_time_step(Real radius_m, Real density_kg_m3, Real shear_modulus_pa,
                               Real poisson_ratio) {
  return std::numbers::pi * radius_m * std::sqrt(density_kg_m3 / shear_modulus_pa) /
         (Real(0.1631) * poisson_ratio + Real(0.8766));
}

/// Maximum overlap of an undamped head-on Hertz impact at relative speed v [m/s] ([J85]
/// §11.4):  δ_max = (15 m* v^2 / (16 E* \sqrt{R*}))^{2/5}   [m].
inline Real hertz_max_overlap(Real youngs_modulus_eff, Real radius_eff, Real mass_eff,
                              Real impact_speed) {
  return std::pow(Real(15) * mass_eff * impact_speed * impact_speed /
                      (Real(16) * youngs_modulus_eff * std::sqrt(radius_eff)),
                  Real(0.4));
}

/// t_c / (δ_max / v) of an undamped Hertz impact: 2 \int_0^1 (1 - x^{5/2})^{-1/2} dx
/// = (4/5) \sqrt{\pi} \Gamma(2/5) / \Gamma(9/10) ([J85] §11.4 prints 2.94).
inline constexpr Real kHertzContactTimeFactor = 2.9432751843247047;

/// Duration of an undamped head-on Hertz impact at relative speed v [m/s] ([J85] §11.4):
///   t_c = 2.943 δ_max / v = 2.868 (m*^2 / (R* E*^2 v))^{1/5}   [s].
inline Real hertz_contact_time(Real youngs_modulus_eff, Real radius_eff, Real mass_eff,
                               Real impact_speed) {
  return kHertzContactTimeFactor *
         hertz_max_overlap(youngs_modulus_eff, radius_eff, mass_eff, impact_speed) / impact_speed;
}

// ---------------------------------------------------------------------------------------------
// What a DEM part asks of the law (law_binding.hpp).

/// Grain-grain parameters of the grains' material; rigid walls of the grain's own elastic
/// constants (as LIGGGHTS' walls of the same material): E* halves the grain-grain one, for a
/// wall radius of infinity.
inline LawPair<HertzMindlin> HertzMindlin::part_laws(const Settings& dem,
                                                     const GranularMaterial& grain) {
  const ElasticMaterial m{youngs_modulus_from_shear(grain.shear_modulus_pa, grain.poisson_ratio),
                          grain.poisson_ratio};
  return {hertz_mindlin_params(m, m, grain.restitution, grain.friction),
          hertz_mindlin_params(m, m, dem.wall_restitution, dem.wall_friction)};
}

/// Rayleigh step of the smallest grain ([LXT05]): the time a Rayleigh wave takes across it; DEM
/// codes run at 10-30 % of it (rayleigh_fraction).
inline LawStep HertzMindlin::part_step(const LawStepQuery& query) {
  LawStep s;
  s.dt_s = query.dem.rayleigh_fraction * rayleigh_time_step(query.radius_min_m, query.density_kg_m3,
                                                            query.grain.shear_modulus_pa,
                                                            query.grain.poisson_ratio);
  s.reason = fmt::format("{} x Rayleigh step of the smallest grain (r = {:.4g} m)",
                         query.dem.rayleigh_fraction, query.radius_min_m);
  return s;
}

}  // namespace crater::dem
