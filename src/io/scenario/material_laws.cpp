// The table of material laws (material_laws.hpp): one entry per law, its keys and its reader.
#include "io/scenario/material_laws.hpp"

#include <fmt/format.h>
#include <cmath>

#include "io/scenario/schema_keys.hpp"
#include "materials/damage/johnson_cook_damage.hpp"
#include "materials/eos/eos.hpp"
#include "materials/strength/strength.hpp"

namespace crater::io {
namespace {

using namespace keys;

// ---- equations of state (sph) --------------------------------------------------------------

void read_jwl(const LawInput& in, MaterialConfig& m) {
  materials::JwlParams p;
  p.rho0_kg_m3 = m.rho0_kg_m3;
  p.a_pa = in.num("a_pa");
  p.b_pa = in.num("b_pa");
  p.r1 = in.num("r1");
  p.r2 = in.num("r2");
  p.omega = in.num("omega");
  p.e0_j_m3 = in.num("e0_j_m3");
  p.d_cj_m_s = in.num("d_cj_m_s");
  in.report(materials::jwl_check(p));
  m.eos = p;
}

MaterialLaw jwl() {
  return {
      .model = "jwl",
      .method = "sph",
      .keys =
          {
              required(
                  positive(real("rho0_kg_m3", "kg/m^3", "Unreacted explosive density rho_0."))),
              required(positive(real("a_pa", "Pa", "JWL A (paper eq. 40)."))),
              required(positive(real("b_pa", "Pa", "JWL B."))),
              required(positive(real("r1", "1", "JWL R1."))),
              required(positive(real("r2", "1", "JWL R2."))),
              required(positive(real("omega", "1", "JWL Grueneisen coefficient omega."))),
              required(positive(
                  real("e0_j_m3", "J/m^3", "Detonation energy per unit initial volume E_0."))),
              required(
                  positive(real("d_cj_m_s", "m/s", "Detonation (Chapman-Jouguet) velocity D."))),
          },
      .read = read_jwl,
  };
}

void read_ideal_gas(const LawInput& in, MaterialConfig& m) {
  materials::IdealGasParams p;
  p.gamma = in.num("gamma");
  in.report(materials::ideal_gas_check(p));
  m.eos = p;
}

MaterialLaw ideal_gas() {
  return {
      .model = "ideal_gas",
      .method = "sph",
      .keys =
          {
              required(
                  positive(real("rho0_kg_m3", "kg/m^3", "Reference density (default initial)."))),
              required(positive(real("gamma", "1", "Ratio of specific heats; > 1."))),
          },
      .read = read_ideal_gas,
  };
}

void read_tait(const LawInput& in, MaterialConfig& m) {
  materials::TaitParams p;
  p.rho0_kg_m3 = m.rho0_kg_m3;
  p.c0_m_s = in.num("c0_m_s");
  p.gamma = in.num("gamma");
  p.background_pa = in.num("background_pa");
  in.report(materials::tait_check(p));
  m.eos = p;
}

MaterialLaw tait() {
  return {
      .model = "tait",
      .method = "sph",
      .keys =
          {
              required(positive(real("rho0_kg_m3", "kg/m^3", "Reference density rho_0 (eq. 35)."))),
              required(positive(
                  real("c0_m_s", "m/s", "Reference sound speed; B = rho_0 c_0^2 / gamma."))),
              with_default(positive(real("gamma", "1", "Tait exponent.")), "7"),
              with_default(real("background_pa", "Pa", "Background pressure added to eq. 35."),
                           "0"),
          },
      .read = read_tait,
  };
}

// ---- grains (dem) ----------------------------------------------------------------------------

void read_granular(const LawInput& in, MaterialConfig& m) {
  m.granular.shear_modulus_pa = in.num("shear_modulus_pa");
  m.granular.poisson_ratio = in.num("poisson_ratio");
  m.granular.friction = in.num("friction");
  m.granular.restitution = in.num("restitution");
}

MaterialLaw granular() {
  return {
      .model = "granular",
      .method = "dem",
      .keys =
          {
              required(positive(real("rho0_kg_m3", "kg/m^3", "Grain (solid) density."))),
              required(positive(real("shear_modulus_pa", "Pa", "Grain shear modulus G."))),
              required(
                  at_most(at_least(real("poisson_ratio", "1", "Grain Poisson's ratio."), 0), 0.5)),
              required(
                  at_least(real("friction", "1", "Grain-grain Coulomb friction coefficient."), 0)),
              required(at_most(positive(real("restitution", "1",
                                             "Normal coefficient of restitution (sets the "
                                             "contact damping).")),
                               1)),
          },
      .read = read_granular,
  };
}

// ---- strength laws (fem) ---------------------------------------------------------------------

// The keys and constants every solid has.
std::vector<KeySchema> elastic_keys() {
  return {
      required(positive(real("rho0_kg_m3", "kg/m^3", "Density of the undeformed solid."))),
      required(positive(real("youngs_modulus_pa", "Pa", "Young's modulus E."))),
      required(
          at_most(at_least(real("poisson_ratio", "1", "Poisson's ratio; below 0.5."), 0), 0.4999)),
  };
}
std::vector<KeySchema> elastic_keys_and(const std::vector<KeySchema>& own) {
  std::vector<KeySchema> k = elastic_keys();
  k.insert(k.end(), own.begin(), own.end());
  return k;
}
materials::ElasticParams read_elastic_constants(const LawInput& in) {
  return {.youngs_modulus_pa = in.num("youngs_modulus_pa"),
          .poisson_ratio = in.num("poisson_ratio")};
}

void read_elastic(const LawInput& in, MaterialConfig& m) {
  m.solid.strength = read_elastic_constants(in);
  in.report(materials::strength_check(m.solid.strength));
}

MaterialLaw elastic() {
  return {.model = "elastic", .method = "fem", .keys = elastic_keys(), .read = read_elastic};
}

TableSchema make_jc_damage() {
  TableSchema t{"materials.damage",
                "Johnson-Cook damage (Johnson & Cook 1985): D accumulates d(eps_p) / eps_f with "
                "eps_f = [D1 + D2 exp(D3 sigma*)] [1 + D4 ln(rate*)] [1 + D5 T*].",
                {},
                {},
                {}};
  t.keys = {
      required(real("d1", "1", "D1.")),
      required(real("d2", "1", "D2.")),
      required(real("d3", "1", "D3.")),
      with_default(real("d4", "1", "D4 (rate)."), "0"),
      with_default(real("d5", "1", "D5 (temperature)."), "0"),
  };
  return t;
}
const TableSchema& jc_damage_schema() {
  static const TableSchema s = make_jc_damage();
  return s;
}

// [materials.damage] of a Johnson-Cook material; its rate and temperatures are the law's.
void read_jc_damage(const LawInput& in, const materials::JohnsonCookParams& p, MaterialConfig& m) {
  const toml::node* dn = in.table.get("damage");
  if (!dn) return;
  const auto& dt = *dn->as_table();
  materials::JohnsonCookDamageParams d;
  d.d1 = reader::num(dt, "d1");
  d.d2 = reader::num(dt, "d2");
  d.d3 = reader::num(dt, "d3");
  d.d4 = reader::num(dt, "d4");
  d.d5 = reader::num(dt, "d5");
  d.reference_strain_rate_1_s = p.reference_strain_rate_1_s;
  d.room_temperature_k = p.room_temperature_k;
  d.melt_temperature_k = p.melt_temperature_k;
  // The failure strain at zero triaxiality must be positive, or every element fails at
  // its first plastic step.
  if (!(d.d1 + d.d2 > 0))
    in.errors.add(where_of(dt, in.where), in.key + ".damage",
                  fmt::format("expected D1 + D2 > 0 (the failure strain at zero triaxiality), "
                              "got {}",
                              d.d1 + d.d2));
  m.solid.damage = d;
}

void read_johnson_cook(const LawInput& in, MaterialConfig& m) {
  materials::JohnsonCookParams p;
  p.elastic = read_elastic_constants(in);
  p.a_pa = in.num("a_pa");
  p.b_pa = in.num("b_pa");
  p.n = in.num("n");
  p.c = in.num("c");
  p.m = in.num("m");
  p.reference_strain_rate_1_s = in.num("reference_strain_rate_1_s");
  p.thermal_softening = in.boolean("thermal_softening");
  p.room_temperature_k = in.num("room_temperature_k");
  p.melt_temperature_k = in.num("melt_temperature_k");
  p.specific_heat_j_kg_k = in.num("specific_heat_j_kg_k");
  p.taylor_quinney = in.num("taylor_quinney");
  if (!(p.melt_temperature_k > p.room_temperature_k))
    in.error("melt_temperature_k",
             fmt::format("expected a melting temperature above room_temperature_k = {} K, got {} K",
                         p.room_temperature_k, p.melt_temperature_k));
  m.solid.strength = p;
  read_jc_damage(in, p, m);
  in.report(materials::strength_check(m.solid.strength));
}

MaterialLaw johnson_cook() {
  return {
      .model = "johnson_cook",
      .method = "fem",
      .keys = elastic_keys_and({
          required(
              positive(real("a_pa", "Pa", "Johnson-Cook A, the initial yield stress (eq. 41)."))),
          required(at_least(real("b_pa", "Pa", "Johnson-Cook B, hardening modulus."), 0)),
          required(positive(real("n", "1", "Johnson-Cook hardening exponent n."))),
          with_default(at_least(real("c", "1", "Johnson-Cook strain-rate coefficient C."), 0), "0"),
          with_default(positive(real("m", "1", "Johnson-Cook thermal softening exponent m.")), "1"),
          with_default(positive(real("reference_strain_rate_1_s", "1/s",
                                     "Reference plastic strain rate of the rate term (eq. 41).")),
                       "1.0"),
          with_default(of_type(real("thermal_softening", "",
                                    "Use the (1 - T*^m) term with adiabatic heating (off in the "
                                    "paper)."),
                               KeyType::Bool),
                       "false"),
          with_default(positive(real("room_temperature_k", "K", "T_room of T*.")), "293.15"),
          with_default(positive(real("melt_temperature_k", "K", "T_melt of T*.")), "1793.0"),
          with_default(positive(real("specific_heat_j_kg_k", "J/(kg K)",
                                     "Specific heat for adiabatic heating.")),
                       "486.0"),
          with_default(at_most(at_least(real("taylor_quinney", "1",
                                             "Fraction of plastic work turned into heat."),
                                        0),
                               1),
                       "0.9"),
          absent_means_unset(
              sub("damage", KeyType::Table, jc_damage_schema(),
                  "Johnson-Cook damage; elements erode at D = 1. Unset: no damage, no erosion.")),
      }),
      .read = read_johnson_cook,
  };
}

void read_drucker_prager(const LawInput& in, MaterialConfig& m) {
  const materials::ElasticParams elastic = read_elastic_constants(in);
  const Real phi = in.num("friction_angle_deg") * M_PI / 180;
  const Real psi =
      in.opt_num("dilation_angle_deg").value_or(in.num("friction_angle_deg")) * M_PI / 180;
  const std::string fit = in.str("fit");
  const auto f = fit == "extension"      ? materials::MohrCoulombFit::kExtensionCone
                 : fit == "plane_strain" ? materials::MohrCoulombFit::kPlaneStrain
                                         : materials::MohrCoulombFit::kCompressionCone;
  if (psi > phi + 1e-12)
    in.error("dilation_angle_deg",
             "expected a dilation angle at most the friction angle (more dilation than "
             "friction is not admissible)");
  m.solid.strength =
      materials::drucker_prager_from_mohr_coulomb(elastic, in.num("cohesion_pa"), phi, psi, f);
  in.report(materials::strength_check(m.solid.strength));
}

MaterialLaw drucker_prager() {
  return {
      .model = "drucker_prager",
      .method = "fem",
      .keys = elastic_keys_and({
          required(at_least(real("cohesion_pa", "Pa", "Mohr-Coulomb cohesion c."), 0)),
          required(at_most(
              at_least(real("friction_angle_deg", "deg", "Mohr-Coulomb friction angle phi."), 0),
              89)),
          at_most(at_least(real("dilation_angle_deg", "deg",
                                "Dilation angle psi (psi = phi: associative). Unset: phi."),
                           0),
                  89),
          with_default(choice("fit", {"compression", "extension", "plane_strain"},
                              "Which Mohr-Coulomb condition the Drucker-Prager cone matches: "
                              "the triaxial compression or extension meridian, or the plane-"
                              "strain collapse load."),
                       "\"compression\""),
      }),
      .read = read_drucker_prager,
  };
}

// What each method's parts take, in words: for the `model` key's help and the error of a part
// given a material of another method. {} stands for the method's models.
struct MethodWords {
  const char* method;
  const char* needs;  // "method \"sph\" needs <this>"
  const char* help;   // a phrase of the `model` key's help
  bool quoted;        // the models in quotes in `needs`
};
constexpr MethodWords kMethodWords[] = {
    {"sph", "an equation-of-state material ({})", "an equation of state for SPH parts ({})", false},
    {"dem", "a {} material", "{} for DEM parts", true},
    {"fem", "a solid material ({})", "a strength law for FEM parts ({})", false},
};

std::string models_of(const char* method, bool quoted) {
  std::string s;
  for (const MaterialLaw& law : material_laws())
    if (law.method == method)
      s += (s.empty() ? "" : ", ") + (quoted ? "\"" + law.model + "\"" : law.model);
  return s;
}

const MethodWords& words_of(const std::string& method) {
  for (const MethodWords& w : kMethodWords)
    if (method == w.method) return w;
  throw std::logic_error("no method " + method);
}

std::string help_of(const char* method) {
  const MethodWords& w = words_of(method);
  return fmt::format(fmt::runtime(w.help), models_of(w.method, false));
}

}  // namespace

// The table: adding a law is one entry here (and its header in materials/).
const std::vector<MaterialLaw>& material_laws() {
  static const std::vector<MaterialLaw> laws = {
      jwl(), ideal_gas(), tait(), granular(), elastic(), johnson_cook(), drucker_prager(),
  };
  return laws;
}

const MaterialLaw& material_law(const std::string& model) {
  for (const MaterialLaw& law : material_laws())
    if (law.model == model) return law;
  throw std::logic_error("no material law " + model);  // the schema accepts only the table's
}

std::vector<std::string> material_models() {
  std::vector<std::string> models;
  for (const MaterialLaw& law : material_laws())
    models.push_back(law.model);
  return models;
}

std::string material_model_doc() {
  return "The law: " + help_of("sph") + ", " + help_of("dem") + ", or " + help_of("fem") + ".";
}

std::string materials_of_method(const std::string& method) {
  const MethodWords& w = words_of(method);
  return fmt::format(fmt::runtime(w.needs), models_of(w.method, w.quoted));
}

}  // namespace crater::io
