// Unit tests of scenario loading (src/io/scenario/): defaults, errors reported together with
// file, line and key, and --set overrides by index and by name.
#include <gtest/gtest.h>

#include <string>
#include <variant>
#include <vector>

#include "io/scenario/load.hpp"
#include "io/scenario/validate.hpp"

namespace crater::io {
namespace {

// A small valid 2D scenario; line numbers below refer to this text (line 1 = [scenario]).
const std::string kBase = R"([scenario]
name = "unit"
dimension = 2
end_time_s = 2.0e-5

[domain]
min_m = [-1.0, -1.0]
max_m = [1.0, 1.0]

[[materials]]
name = "tnt"
model = "jwl"
rho0_kg_m3 = 1630.0
a_pa = 373.8e9
b_pa = 3.747e9
r1 = 4.15
r2 = 0.90
omega = 0.35
e0_j_m3 = 6.0e9
d_cj_m_s = 6930.0

[[materials]]
name = "air"
model = "ideal_gas"
rho0_kg_m3 = 1.2
gamma = 1.4

[[parts]]
name = "charge"
method = "sph"
material = "tnt"
spacing_m = 0.01
region = { type = "disk", center_m = [0.0, 0.0], radius_m = 0.1 }

[[parts]]
name = "gas"
method = "sph"
material = "air"
spacing_m = 0.02
region = { type = "box", min_m = [0.2, -0.2], max_m = [0.6, 0.2] }
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

// Every error of a failed load (one for a plain InputError).
std::vector<InputError> load_errors(const std::string& text,
                                    const std::vector<std::string>& overrides = {}) {
  try {
    load_scenario_text(text, "unit.toml", overrides);
  } catch (const InputErrors& e) {
    return e.all();
  } catch (const InputError& e) {
    return {e};
  }
  ADD_FAILURE() << "expected the scenario to be rejected";
  return {};
}

const InputError* find_key(const std::vector<InputError>& errors, const std::string& key) {
  for (const auto& e : errors)
    if (e.key() == key) return &e;
  return nullptr;
}

std::string all_messages(const std::vector<InputError>& errors) {
  std::string s;
  for (const auto& e : errors)
    s += std::string(e.what()) + "\n";
  return s;
}

TEST(ScenarioLoad, BaseScenarioLoads) {
  const Config c = load_scenario_text(kBase, "unit.toml", {});
  EXPECT_EQ(c.name, "unit");
  EXPECT_EQ(c.dimension, 2);
  EXPECT_DOUBLE_EQ(c.end_time_s, 2.0e-5);
  ASSERT_EQ(c.materials.size(), 2u);
  ASSERT_EQ(c.parts.size(), 2u);
  EXPECT_EQ(c.parts[0].name, "charge");
  EXPECT_EQ(c.parts[0].material, 0u);
  EXPECT_EQ(c.parts[1].material, 1u);
  EXPECT_TRUE(std::holds_alternative<materials::JwlParams>(c.materials[0].eos));
  EXPECT_TRUE(std::holds_alternative<materials::IdealGasParams>(c.materials[1].eos));
  EXPECT_EQ(c.file, "unit.toml");
  EXPECT_EQ(c.hash.size(), 16u);
}

TEST(ScenarioLoad, DefaultsAreFilled) {
  const Config c = load_scenario_text(kBase, "unit.toml", {});
  EXPECT_DOUBLE_EQ(c.time.safety_factor, 0.9);
  EXPECT_FALSE(c.time.fixed_dt_s.has_value());
  EXPECT_EQ(c.time.max_steps, 0);
  EXPECT_DOUBLE_EQ(c.output.interval_s, c.end_time_s / 20);  // unset: end_time_s / 20
  EXPECT_EQ(c.output.history_every, 10);
  EXPECT_TRUE(c.output.vtu);
  EXPECT_EQ(c.output.vtu_encoding, VtuEncoding::Appended);
  EXPECT_EQ(c.description, "");
  for (int d = 0; d < 3; ++d)
    EXPECT_EQ(c.domain.gravity_m_s2[d], 0.0);
  const auto& sph = c.parts[0].sph();
  EXPECT_EQ(sph.kernel, sph::KernelKind::WendlandC2);
  EXPECT_DOUBLE_EQ(sph.h_factor, 1.3);
  EXPECT_DOUBLE_EQ(sph.av_alpha, 1.0);
  EXPECT_DOUBLE_EQ(sph.av_beta, 2.0);
  EXPECT_DOUBLE_EQ(sph.cfl, 0.3);
  EXPECT_FALSE(c.parts[0].initial.density_kg_m3.has_value());
  EXPECT_FALSE(c.parts[0].initial.pressure_pa.has_value());
  EXPECT_TRUE(c.parts[0].detonations.empty());
  // The effective scenario written with the run holds the defaults.
  EXPECT_NE(c.effective_toml.find("safety_factor"), std::string::npos) << c.effective_toml;
}

TEST(ScenarioLoad, DomainOutflowDefaultsToStopAndIsAChoice) {
  EXPECT_EQ(load_scenario_text(kBase, "unit.toml", {}).domain.outflow, Outflow::Stop);
  EXPECT_EQ(load_scenario_text(kBase, "unit.toml", {"domain.outflow=\"remove\""}).domain.outflow,
            Outflow::Remove);
  const auto errors = load_errors(kBase, {"domain.outflow=\"delete\""});
  ASSERT_NE(find_key(errors, "domain.outflow"), nullptr) << all_messages(errors);
}

TEST(ScenarioLoad, DimensionDefaultsToTwo) {
  const Config c = load_scenario_text(replace(kBase, "dimension = 2\n", ""), "unit.toml", {});
  EXPECT_EQ(c.dimension, 2);
}

TEST(ScenarioLoad, ExplicitValuesWinOverDefaults) {
  const std::string text =
      replace(kBase, "[domain]",
              "[time]\nsafety_factor = 0.5\n\n[output]\ninterval_s = 1.0e-6\n\n[domain]");
  const Config c = load_scenario_text(text, "unit.toml", {});
  EXPECT_DOUBLE_EQ(c.time.safety_factor, 0.5);
  EXPECT_DOUBLE_EQ(c.output.interval_s, 1.0e-6);
}

TEST(ScenarioLoad, HashDependsOnContentOnly) {
  const Config a = load_scenario_text(kBase, "a.toml", {});
  const Config b = load_scenario_text(kBase, "b.toml", {});
  const Config c = load_scenario_text(kBase, "a.toml", {"time.safety_factor=0.5"});
  EXPECT_EQ(a.hash, b.hash);
  EXPECT_NE(a.hash, c.hash);
}

TEST(ScenarioLoad, SeveralErrorsAreReportedTogether) {
  // Three independent problems: a wrong type, an out-of-range value, an unknown key.
  std::string text = replace(kBase, "end_time_s = 2.0e-5", "end_time_s = \"soon\"");  // line 4
  text = replace(text, "gamma = 1.4", "gamma = 1.4\ngama = 1.4");  // new line 27: later lines +1
  text = replace(text, "spacing_m = 0.02", "spacing_m = -0.02");   // line 39 + 1
  const auto errors = load_errors(text);
  ASSERT_GE(errors.size(), 3u) << all_messages(errors);

  const InputError* e = find_key(errors, "scenario.end_time_s");
  ASSERT_NE(e, nullptr) << all_messages(errors);
  EXPECT_EQ(e->where().file, "unit.toml");
  EXPECT_EQ(e->where().line, 4);
  EXPECT_NE(std::string(e->what()).find("unit.toml:4"), std::string::npos) << e->what();
  EXPECT_NE(std::string(e->what()).find("key 'scenario.end_time_s'"), std::string::npos);

  e = find_key(errors, "parts[1].spacing_m");
  ASSERT_NE(e, nullptr) << all_messages(errors);
  EXPECT_EQ(e->where().line, 40);

  e = find_key(errors, "materials[1].gama");
  ASSERT_NE(e, nullptr) << all_messages(errors);
  EXPECT_EQ(e->where().line, 27);
  EXPECT_NE(std::string(e->what()).find("did you mean 'gamma'"), std::string::npos) << e->what();
}

TEST(ScenarioLoad, CrossCheckErrorsAreReportedTogether) {
  // Unknown material and overlapping bodies, both found after validation.
  std::string text = replace(kBase, "material = \"air\"", "material = \"aire\"");
  text = replace(text, "min_m = [0.2, -0.2]", "min_m = [0.05, -0.2]");
  const auto errors = load_errors(text);
  const InputError* e = find_key(errors, "parts[1].material");
  ASSERT_NE(e, nullptr) << all_messages(errors);
  EXPECT_NE(std::string(e->what()).find("unknown material 'aire'"), std::string::npos);
  e = find_key(errors, "parts[1].region");
  ASSERT_NE(e, nullptr) << all_messages(errors);
  EXPECT_NE(std::string(e->what()).find("overlap"), std::string::npos) << e->what();
  EXPECT_EQ(e->where().line, 40);  // region of the second part
}

TEST(ScenarioLoad, MissingKeyNamesTheTableLine) {
  const auto errors = load_errors(replace(kBase, "a_pa = 373.8e9\n", ""));
  const InputError* e = find_key(errors, "materials[0].a_pa");
  ASSERT_NE(e, nullptr) << all_messages(errors);
  EXPECT_EQ(e->where().line, 10);  // [[materials]]
}

TEST(ScenarioLoad, SyntaxErrorNamesTheLine) {
  const auto errors = load_errors(replace(kBase, "name = \"unit\"", "name = \"unit"));
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].where().line, 2);
  EXPECT_NE(std::string(errors[0].what()).find("TOML syntax error"), std::string::npos);
}

TEST(ScenarioLoad, SetByIndex) {
  const Config c = load_scenario_text(kBase, "unit.toml", {"parts.1.spacing_m=0.01"});
  EXPECT_DOUBLE_EQ(c.parts[1].spacing_m, 0.01);
  EXPECT_DOUBLE_EQ(c.parts[0].spacing_m, 0.01);
}

TEST(ScenarioLoad, SetByName) {
  const Config c = load_scenario_text(kBase, "unit.toml",
                                      {"parts.gas.spacing_m=0.005", "materials.air.gamma=1.67"});
  EXPECT_DOUBLE_EQ(c.parts[1].spacing_m, 0.005);
  EXPECT_DOUBLE_EQ(c.parts[0].spacing_m, 0.01);
  EXPECT_DOUBLE_EQ(std::get<materials::IdealGasParams>(c.materials[1].eos).gamma, 1.67);
}

TEST(ScenarioLoad, SetTopLevelAndNewSubTable) {
  const Config c = load_scenario_text(
      kBase, "unit.toml",
      {"time.safety_factor=0.25", "parts.charge.sph.h_factor=2.0", "scenario.name=renamed"});
  EXPECT_DOUBLE_EQ(c.time.safety_factor, 0.25);
  EXPECT_DOUBLE_EQ(c.parts[0].sph().h_factor, 2.0);
  EXPECT_EQ(c.name, "renamed");  // a bare word is taken as a string
}

TEST(ScenarioLoad, SetErrorsNameTheKey) {
  auto errors = load_errors(kBase, {"time.safety_factor=\"fast\""});
  ASSERT_NE(find_key(errors, "time.safety_factor"), nullptr) << all_messages(errors);

  errors = load_errors(kBase, {"time.safty_factor=0.5"});
  ASSERT_NE(find_key(errors, "time.safty_factor"), nullptr) << all_messages(errors);

  errors = load_errors(kBase, {"parts.nosuch.spacing_m=0.01"});
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(std::string(errors[0].what()).find("no entry 'nosuch'"), std::string::npos)
      << errors[0].what();

  errors = load_errors(kBase, {"parts.7.spacing_m=0.01"});
  ASSERT_EQ(errors.size(), 1u);

  errors = load_errors(kBase, {"time.safety_factor"});
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(std::string(errors[0].what()).find("dotted.key=VALUE"), std::string::npos);
}

TEST(ScenarioLoad, SetIsValidatedLikeTheFile) {
  const auto errors = load_errors(kBase, {"parts.charge.spacing_m=0"});
  const InputError* e = find_key(errors, "parts[0].spacing_m");
  ASSERT_NE(e, nullptr) << all_messages(errors);
  // The location is the --set argument, not a line of the file.
  EXPECT_NE(e->where().file.find("--set"), std::string::npos) << e->what();
}

TEST(ScenarioLoad, NulByteIsRejected) {
  std::string text = kBase;
  text[5] = '\0';
  EXPECT_THROW(load_scenario_text(text, "unit.toml", {}), InputError);
}

}  // namespace
}  // namespace crater::io
