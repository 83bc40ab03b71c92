// The scenario reader (reader.hpp): [[materials]].
#include <fmt/format.h>
#include <toml++/toml.h>
#include <algorithm>
#include <cmath>

#include "io/scenario/reader.hpp"

namespace crater::io::reader {

void Builder::read_materials(Config& c, const SourceLocation& top) {
  const auto& arr = *root_.get("materials")->as_array();
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const auto& t = *arr.get(i)->as_table();
    const SourceLocation w = where_of(t, top);
    const std::string key = fmt::format("materials[{}]", i);
    MaterialConfig m;
    m.name = str(t, "name");
    m.model = str(t, "model");
    m.where = w;
    m.rho0_kg_m3 = num(t, "rho0_kg_m3");
    for (const auto& other : c.materials)
      if (other.name == m.name)
        error(loc(t, "name", w), key + ".name",
              fmt::format("duplicate material name '{}' (first at line {})", m.name,
                          other.where.line));
    if (m.model == "jwl") {
      materials::JwlParams p;
      p.rho0_kg_m3 = m.rho0_kg_m3;
      p.a_pa = num(t, "a_pa");
      p.b_pa = num(t, "b_pa");
      p.r1 = num(t, "r1");
      p.r2 = num(t, "r2");
      p.omega = num(t, "omega");
      p.e0_j_m3 = num(t, "e0_j_m3");
      p.d_cj_m_s = num(t, "d_cj_m_s");
      report(errors_, t, w, key, materials::jwl_check(p));
      m.eos = p;
    } else if (m.model == "granular") {
      m.granular.shear_modulus_pa = num(t, "shear_modulus_pa");
      m.granular.poisson_ratio = num(t, "poisson_ratio");
      m.granular.friction = num(t, "friction");
      m.granular.restitution = num(t, "restitution");
    } else if (m.model == "elastic" || m.model == "johnson_cook" || m.model == "drucker_prager") {
      read_solid(t, w, key, m);
    } else if (m.model == "ideal_gas") {
      materials::IdealGasParams p;
      p.gamma = num(t, "gamma");
      report(errors_, t, w, key, materials::ideal_gas_check(p));
      m.eos = p;
    } else {
      materials::TaitParams p;
      p.rho0_kg_m3 = m.rho0_kg_m3;
      p.c0_m_s = num(t, "c0_m_s");
      p.gamma = num(t, "gamma");
      p.background_pa = num(t, "background_pa");
      report(errors_, t, w, key, materials::tait_check(p));
      m.eos = p;
    }
    c.materials.push_back(std::move(m));
  }
}

void Builder::read_solid(const toml::table& t, const SourceLocation& w, const std::string& key,
                         MaterialConfig& m) {
  const materials::ElasticParams elastic{.youngs_modulus_pa = num(t, "youngs_modulus_pa"),
                                         .poisson_ratio = num(t, "poisson_ratio")};
  if (m.model == "elastic") {
    m.solid.strength = elastic;
  } else if (m.model == "johnson_cook") {
    materials::JohnsonCookParams p;
    p.elastic = elastic;
    p.a_pa = num(t, "a_pa");
    p.b_pa = num(t, "b_pa");
    p.n = num(t, "n");
    p.c = num(t, "c");
    p.m = num(t, "m");
    p.reference_strain_rate_1_s = num(t, "reference_strain_rate_1_s");
    p.thermal_softening = t.get("thermal_softening")->as_boolean()->get();
    p.room_temperature_k = num(t, "room_temperature_k");
    p.melt_temperature_k = num(t, "melt_temperature_k");
    p.specific_heat_j_kg_k = num(t, "specific_heat_j_kg_k");
    p.taylor_quinney = num(t, "taylor_quinney");
    if (!(p.melt_temperature_k > p.room_temperature_k))
      error(loc(t, "melt_temperature_k", w), key + ".melt_temperature_k",
            fmt::format("expected a melting temperature above room_temperature_k = {} K, got {} K",
                        p.room_temperature_k, p.melt_temperature_k));
    m.solid.strength = p;
    if (const toml::node* dn = t.get("damage")) {
      const auto& dt = *dn->as_table();
      materials::JohnsonCookDamageParams d;
      d.d1 = num(dt, "d1");
      d.d2 = num(dt, "d2");
      d.d3 = num(dt, "d3");
      d.d4 = num(dt, "d4");
      d.d5 = num(dt, "d5");
      d.reference_strain_rate_1_s = p.reference_strain_rate_1_s;
      d.room_temperature_k = p.room_temperature_k;
      d.melt_temperature_k = p.melt_temperature_k;
      // The failure strain at zero triaxiality must be positive, or every element fails at
      // its first plastic step.
      if (!(d.d1 + d.d2 > 0))
        error(where_of(dt, w), key + ".damage",
              fmt::format("expected D1 + D2 > 0 (the failure strain at zero triaxiality), got "
                          "{}",
                          d.d1 + d.d2));
      m.solid.damage = d;
    }
  } else {
    const Real phi = num(t, "friction_angle_deg") * M_PI / 180;
    const Real psi =
        opt_num(t, "dilation_angle_deg").value_or(num(t, "friction_angle_deg")) * M_PI / 180;
    const std::string fit = str(t, "fit");
    const auto f = fit == "extension"      ? materials::MohrCoulombFit::kExtensionCone
                   : fit == "plane_strain" ? materials::MohrCoulombFit::kPlaneStrain
                                           : materials::MohrCoulombFit::kCompressionCone;
    if (psi > phi + 1e-12)
      error(loc(t, "dilation_angle_deg", w), key + ".dilation_angle_deg",
            "expected a dilation angle at most the friction angle (more dilation than "
            "friction is not admissible)");
    m.solid.strength =
        materials::drucker_prager_from_mohr_coulomb(elastic, num(t, "cohesion_pa"), phi, psi, f);
  }
  report(errors_, t, w, key, materials::strength_check(m.solid.strength));
}

}  // namespace crater::io::reader
