// The table of material laws (material_laws.hpp): one entry per law, its keys and its reader.
#include "io/scenario/material_laws.hpp"

#include <fmt/format.h>
#include <cmath>
#include <limits>
#include <utility>

#include "io/scenario/schema_keys.hpp"
#include "materials/damage/johnson_cook_damage.hpp"
#include "materials/eos/eos.hpp"
#include "materials/strength/strength.hpp"

namespace crater::io {
namespace {

using namespace keys;

using Reader = decltype(MaterialLaw::read);

// An equation of state: a law of SPH parts.
MaterialLaw equation_of_state(const char* model, std::vector<KeySchema> keys, Reader read) {
  return {.model = model, .method = Method::Sph, .keys = std::move(keys), .read = read};
}

// A law of DEM grains.
MaterialLaw grain_law(const char* model, std::vector<KeySchema> keys, Reader read) {
  return {.model = model, .method = Method::Dem, .keys = std::move(keys), .read = read};
}

// ---- equations of state (sph) --------------------------------------------------------------

void read_jwl(const LawInput& in, MaterialConfig& m) {
  const materials::JwlParams p{.rho0_kg_m3 = m.rho0_kg_m3,
                               .a_pa = in.num("a_pa"),
                               .b_pa = in.num("b_pa"),
                               .r1 = in.num("r1"),
                               .r2 = in.num("r2"),
                               .omega = in.num("omega"),
                               .e0_j_m3 = in.num("e0_j_m3"),
                               .d_cj_m_s = in.num("d_cj_m_s")};
  in.report(materials::jwl_check(p));
  m.eos = p;
}

MaterialLaw jwl() {
  return equation_of_state(
      "jwl",
      {
          required(positive(real("rho0_kg_m3", "kg/m^3", "Unreacted explosive density rho_0."))),
          required(positive(real("a_pa", "Pa", "JWL A (paper eq. 40)."))),
          required(positive(real("b_pa", "Pa", "JWL B."))),
          required(positive(real("r1", "1", "JWL R1."))),
          required(positive(real("r2", "1", "JWL R2."))),
          required(positive(real("omega", "1", "JWL Grueneisen coefficient omega."))),
          required(
              positive(real("e0_j_m3", "J/m^3", "Detonation energy per unit initial volume E_0."))),
          required(positive(real("d_cj_m_s", "m/s", "Detonation (Chapman-Jouguet) velocity D."))),
      },
      read_jwl);
}

void read_ideal_gas(const LawInput& in, MaterialConfig& m) {
  const materials::IdealGasParams p{.gamma = in.num("gamma")};
  in.report(materials::ideal_gas_check(p));
  m.eos = p;
}

MaterialLaw ideal_gas() {
  return equation_of_state(
      "ideal_gas",
      {
          required(positive(real("rho0_kg_m3", "kg/m^3", "Reference density (default initial)."))),
          required(positive(real("gamma", "1", "Ratio of specific heats; > 1."))),
      },
      read_ideal_gas);
}

void read_tait(const LawInput& in, MaterialConfig& m) {
  const materials::TaitParams p{.rho0_kg_m3 = m.rho0_kg_m3,
                                .c0_m_s = in.num("c0_m_s"),
                                .gamma = in.num("gamma"),
                                .background_pa = in.num("background_pa")};
  in.report(materials::tait_check(p));
  m.eos = p;
}

MaterialLaw tait() {
  return equation_of_state(
      "tait",
      {
          required(positive(real("rho0_kg_m3", "kg/m^3", "Reference density rho_0 (eq. 35)."))),
          required(
              positive(real("c0_m_s", "m/s", "Reference sound speed; B = rho_0 c_0^2 / gamma."))),
          with_default(positive(real("gamma", "1", "Tait exponent.")), "7"),
          with_default(real("background_pa", "Pa", "Background pressure added to eq. 35."), "0"),
      },
      read_tait);
}

// ---- grains (dem) ----------------------------------------------------------------------------

void read_granular(const LawInput& in, MaterialConfig& m) {
  m.granular = {.shear_modulus_pa = in.num("shear_modulus_pa"),
                .poisson_ratio = in.num("poisson_ratio"),
                .friction = in.num("friction"),
                .restitution = in.num("restitution")};
}

MaterialLaw granular() {
  return grain_law(
      "granular",
      {
          required(positive(real("rho0_kg_m3", "kg/m^3", "Grain (solid) density."))),
          required(positive(real("shear_modulus_pa", "Pa", "Grain shear modulus G."))),
          required(at_most(at_least(real("poisson_ratio", "1", "Grain Poisson's ratio."), 0), 0.5)),
          required(at_least(real("friction", "1", "Grain-grain Coulomb friction coefficient."), 0)),
          required(at_most(positive(real("restitution", "1",
                                         "Normal coefficient of restitution (sets the "
                                         "contact damping).")),
                           1)),
      },
      read_granular);
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

// A strength law of FEM parts: the keys every solid has, then its own.
MaterialLaw strength_law(const char* model, const std::vector<KeySchema>& own, Reader read) {
  return {.model = model, .method = Method::Fem, .keys = elastic_keys_and(own), .read = read};
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
  return strength_law("elastic", {}, read_elastic);
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
  const materials::JohnsonCookDamageParams d{
      .d1 = reader::num(dt, "d1"),
      .d2 = reader::num(dt, "d2"),
      .d3 = reader::num(dt, "d3"),
      .d4 = reader::num(dt, "d4"),
      .d5 = reader::num(dt, "d5"),
      .reference_strain_rate_1_s = p.reference_strain_rate_1_s,
      .room_temperature_k = p.room_temperature_k,
      .melt_temperature_k = p.melt_temperature_k};
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
  const materials::JohnsonCookParams p{
      .elastic = read_elastic_constants(in),
      .a_pa = in.num("a_pa"),
      .b_pa = in.num("b_pa"),
      .n = in.num("n"),
      .c = in.num("c"),
      .m = in.num("m"),
      .reference_strain_rate_1_s = in.num("reference_strain_rate_1_s"),
      .room_temperature_k = in.num("room_temperature_k"),
      // Unset: no temperature term (T* = 0 at any temperature), in the damage's D5 either.
      .melt_temperature_k =
          in.opt_num("melt_temperature_k").value_or(std::numeric_limits<Real>::infinity()),
      .thermal_softening = in.boolean("thermal_softening"),
      .taylor_quinney = in.num("taylor_quinney"),
      // Unset: no heating (only thermal_softening heats, and it requires the key).
      .specific_heat_j_kg_k =
          in.opt_num("specific_heat_j_kg_k").value_or(std::numeric_limits<Real>::quiet_NaN())};
  // No steel defaults: a copper or aluminium plate would heat and soften as steel does.
  bool missing = false;
  if (p.thermal_softening)
    for (const char* k : {"melt_temperature_k", "specific_heat_j_kg_k"})
      if (!in.opt_num(k)) {
        in.error(k,
                 "missing: required with thermal_softening = true (the material's own value; "
                 "e.g. steel 1793 K and 486 J/(kg K), copper 1356 K and 383 J/(kg K))");
        missing = true;
      }
  if (missing) return;
  if (!(p.melt_temperature_k > p.room_temperature_k))
    in.error("melt_temperature_k",
             fmt::format("expected a melting temperature above room_temperature_k = {} K, got {} K",
                         p.room_temperature_k, p.melt_temperature_k));
  m.solid.strength = p;
  read_jc_damage(in, p, m);
  in.report(materials::strength_check(m.solid.strength));
}

MaterialLaw johnson_cook() {
  return strength_law(
      "johnson_cook",
      {
          required(
              positive(real("a_pa", "Pa", "Johnson-Cook A, the initial yield stress (eq. 41)."))),
          required(at_least(real("b_pa", "Pa", "Johnson-Cook B, hardening modulus."), 0)),
          required(positive(real("n", "1", "Johnson-Cook hardening exponent n."))),
          with_default(at_least(real("c", "1", "Johnson-Cook strain-rate coefficient C."), 0), "0"),
          with_default(positive(real("m", "1", "Johnson-Cook thermal softening exponent m.")), "1"),
          with_default(positive(real("reference_strain_rate_1_s", "1/s",
                                     "Reference plastic strain rate of the rate term (eq. 41).")),
                       "1.0"),
          with_default(flag("thermal_softening",
                            "Use the (1 - T*^m) term with adiabatic heating (off in the "
                            "paper)."),
                       "false"),
          with_default(positive(real("room_temperature_k", "K",
                                     "T_room of T*; also the temperature a part of this "
                                     "material starts at, unless parts.fem.initial_temperature_k "
                                     "says otherwise.")),
                       "293.15"),
          positive(real("melt_temperature_k", "K",
                        "T_melt of T*. Required with thermal_softening (no steel default). "
                        "Unset otherwise: no temperature term, in the damage's D5 either.")),
          positive(real("specific_heat_j_kg_k", "J/(kg K)",
                        "Specific heat for adiabatic heating. Required with thermal_softening "
                        "(no steel default); unused otherwise.")),
          with_default(at_most(at_least(real("taylor_quinney", "1",
                                             "Fraction of plastic work turned into heat."),
                                        0),
                               1),
                       "0.9"),
          absent_means_unset(
              sub("damage", KeyType::Table, jc_damage_schema(),
                  "Johnson-Cook damage; elements erode at D = 1. Unset: no damage, no erosion.")),
      },
      read_johnson_cook);
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
  return strength_law(
      "drucker_prager",
      {
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
      },
      read_drucker_prager);
}

// Holmquist-Johnson-Cook concrete (materials/strength/holmquist_johnson_cook.hpp): its own
// constants (no youngs_modulus_pa/poisson_ratio: the bulk response is the compaction EOS),
// named as HolmquistJohnsonCookParams; every default is the 48 MPa concrete of [HJC93], so
// `model = "holmquist_johnson_cook"` alone is that concrete.
void read_holmquist_johnson_cook(const LawInput& in, MaterialConfig& m) {
  const materials::HolmquistJohnsonCookParams p{.rho0_kg_m3 = m.rho0_kg_m3,
                                                .shear_modulus_pa = in.num("shear_modulus_pa"),
                                                .a = in.num("a"),
                                                .b = in.num("b"),
                                                .c = in.num("c"),
                                                .n = in.num("n"),
                                                .fc_pa = in.num("fc_pa"),
                                                .t_pa = in.num("t_pa"),
                                                .s_max = in.num("s_max"),
                                                .eps0_per_s = in.num("eps0_per_s"),
                                                .ef_min = in.num("ef_min"),
                                                .d1 = in.num("d1"),
                                                .d2 = in.num("d2"),
                                                .p_crush_pa = in.num("p_crush_pa"),
                                                .mu_crush = in.num("mu_crush"),
                                                .k1_pa = in.num("k1_pa"),
                                                .k2_pa = in.num("k2_pa"),
                                                .k3_pa = in.num("k3_pa"),
                                                .p_lock_pa = in.num("p_lock_pa"),
                                                .mu_lock = in.num("mu_lock")};
  m.solid.strength = materials::holmquist_johnson_cook_law(p);
  m.solid.erode_at_full_damage = in.boolean("erode_at_full_damage");
  in.report(materials::strength_check(m.solid.strength));
}

MaterialLaw holmquist_johnson_cook() {
  auto dimensionless = [](const char* key, const char* doc) { return real(key, "1", doc); };
  return {
      .model = "holmquist_johnson_cook",
      .method = Method::Fem,
      .keys =
          {
              with_default(positive(real("rho0_kg_m3", "kg/m^3",
                                         "Initial density rho_0. Every default of this model is "
                                         "the 48 MPa concrete of Holmquist, Johnson & Cook "
                                         "(1993).")),
                           "2440.0"),
              with_default(positive(real("shear_modulus_pa", "Pa", "Shear modulus G.")), "14.86e9"),
              with_default(positive(dimensionless("a", "Normalized cohesive strength A.")), "0.79"),
              with_default(
                  at_least(dimensionless("b", "Normalized pressure hardening coefficient B."), 0),
                  "1.60"),
              with_default(at_least(dimensionless("c", "Strain-rate coefficient C."), 0), "0.007"),
              with_default(positive(dimensionless("n", "Pressure hardening exponent N.")), "0.61"),
              with_default(positive(real("fc_pa", "Pa",
                                         "Quasi-static uniaxial compressive strength f_c "
                                         "(normalizes pressure and strength).")),
                           "48e6"),
              with_default(positive(real("t_pa", "Pa", "Maximum tensile hydrostatic pressure T.")),
                           "4e6"),
              with_default(positive(dimensionless("s_max", "Normalized maximum strength S_max.")),
                           "7.0"),
              with_default(positive(real("eps0_per_s", "1/s",
                                         "Reference strain rate (no rate effect below it).")),
                           "1.0"),
              with_default(
                  positive(dimensionless("ef_min", "Minimum plastic strain to fracture EF_min.")),
                  "0.01"),
              with_default(at_least(dimensionless("d1", "Damage constant D_1."), 0), "0.04"),
              with_default(at_least(dimensionless("d2", "Damage constant D_2."), 0), "1.0"),
              with_default(positive(real("p_crush_pa", "Pa",
                                         "Crushing pressure P_c (end of the elastic region; "
                                         "K_e = P_c/mu_c).")),
                           "16e6"),
              with_default(positive(dimensionless(
                               "mu_crush", "Crushing volumetric strain mu_c = rho/rho_0 - 1.")),
                           "0.001"),
              with_default(positive(real("k1_pa", "Pa", "Fully dense pressure constant K_1.")),
                           "85e9"),
              with_default(real("k2_pa", "Pa",
                                "Fully dense pressure constant K_2; with K_1 and K_3 the fully "
                                "dense curve must rise monotonically to p_lock_pa."),
                           "-171e9"),
              with_default(real("k3_pa", "Pa", "Fully dense pressure constant K_3."), "208e9"),
              with_default(positive(real("p_lock_pa", "Pa",
                                         "Locking pressure P_l (end of compaction); must exceed "
                                         "p_crush_pa.")),
                           "800e6"),
              with_default(positive(dimensionless(
                               "mu_lock",
                               "Locking volumetric strain mu_l (rho_grain/rho_0 - 1, where the "
                               "fully dense curve has zero pressure); must exceed mu_crush.")),
                           "0.1"),
              with_default(flag("erode_at_full_damage",
                                "Elements erode when the HJC damage D reaches 1 (as Johnson-Cook "
                                "damage does). Off: a fully damaged element stays, carrying "
                                "pressure and the strength B P*^N of comminuted concrete."),
                           "false"),
          },
      .read = read_holmquist_johnson_cook};
}

// What each method's parts take, in words: for the `model` key's help and the error of a part
// given a material of another method. {} stands for the method's models.
struct MethodWords {
  Method method;
  const char* needs;  // "method \"sph\" needs <this>"
  const char* help;   // a phrase of the `model` key's help
  bool quoted;        // the models in quotes in `needs`
};
constexpr MethodWords kMethodWords[] = {
    {Method::Sph, "an equation-of-state material ({})", "an equation of state for SPH parts ({})",
     false},
    {Method::Dem, "a {} material", "{} for DEM parts", true},
    {Method::Fem, "a solid material ({})", "a strength law for FEM parts ({})", false},
};

std::string models_of(Method method, bool quoted) {
  std::string s;
  for (const MaterialLaw& law : material_laws())
    if (law.method == method)
      s += (s.empty() ? "" : ", ") + (quoted ? "\"" + law.model + "\"" : law.model);
  return s;
}

const MethodWords& words_of(Method method) {
  for (const MethodWords& w : kMethodWords)
    if (method == w.method) return w;
  throw std::logic_error(std::string("no method ") + method_name(method));
}

std::string help_of(Method method) {
  const MethodWords& w = words_of(method);
  return fmt::format(fmt::runtime(w.help), models_of(w.method, false));
}

}  // namespace

// The table: adding a law is one entry here (and its header in materials/).
const std::vector<MaterialLaw>& material_laws() {
  static const std::vector<MaterialLaw> laws = {
      jwl(),     ideal_gas(),    tait(),           granular(),
      elastic(), johnson_cook(), drucker_prager(), holmquist_johnson_cook(),
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
  return "The law: " + help_of(Method::Sph) + ", " + help_of(Method::Dem) + ", or " +
         help_of(Method::Fem) + ".";
}

std::string materials_of_method(Method method) {
  const MethodWords& w = words_of(method);
  return fmt::format(fmt::runtime(w.needs), models_of(w.method, w.quoted));
}

}  // namespace crater::io
