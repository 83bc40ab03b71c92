// The material laws a scenario can name (`[[materials]] model`), registered in one table
// (material_laws.cpp): per law its model name, the method whose parts it serves, its keys (the
// schema's variant for that model: type, unit, range, default, help) and the reader that
// builds its parameters from the validated table. The schema (scenario_schema.cpp) and the
// reader (read_materials.cpp, read_parts.cpp) take everything about a law from here; nothing
// else names a model.
//
// Adding an equation of state or a strength law (docs/architecture.md, "How to add"): its
// header in materials/eos/ or materials/strength/ (parameters, equations, *_check and its
// overloads of the law's interface), its alternative in the variant (EosParams in eos.hpp,
// StrengthParams in strength.hpp), then one entry in material_laws.cpp.
#pragma once

#include <string>
#include <vector>

#include "io/scenario/reader.hpp"
#include "io/scenario/schema.hpp"

namespace crater::io {

/// What a law's reader is given: the material's table (validated: its keys present, typed
/// and in range, defaults filled in), where it is, its key ("materials[2]") and where its
/// errors go.
struct LawInput {
  const toml::table& table;
  const SourceLocation& where;
  const std::string& key;
  reader::ErrorList& errors;

  Real num(const char* k) const { return reader::num(table, k); }
  std::optional<Real> opt_num(const char* k) const { return reader::opt_num(table, k); }
  std::string str(const char* k) const { return reader::str(table, k); }
  bool boolean(const char* k) const { return table.get(k)->as_boolean()->get(); }
  /// An error at one of the material's keys.
  void error(const char* k, const std::string& what) const {
    errors.add(reader::loc(table, k, where), key + "." + k, what);
  }
  /// The law's constant problems (its *_check), each at the key of the constant at fault.
  void report(const std::vector<materials::ConstantProblem>& problems) const {
    reader::report(errors, table, where, key, problems);
  }
};

/// One material law of the scenario format.
struct MaterialLaw {
  std::string model;            // the value of `model`, e.g. "tait"
  Method method;                // the method whose parts take it
  std::vector<KeySchema> keys;  // its keys besides `name` and `model`, in the docs' order
  /// Fills the material's parameters (m.eos, m.granular or m.solid; m.rho0_kg_m3 is read).
  void (*read)(const LawInput& in, MaterialConfig& m);
};

/// Every law, in the order of the docs and of the `model` choices.
const std::vector<MaterialLaw>& material_laws();

/// The law of a model the schema accepted.
const MaterialLaw& material_law(const std::string& model);

/// The `model` key's choices and help text, from the table.
std::vector<std::string> material_models();
std::string material_model_doc();

/// What a method's parts take, in words ("an equation-of-state material (jwl, ...)").
std::string materials_of_method(Method method);

}  // namespace crater::io
