// The scenario reader (reader.hpp): [[materials]]; each law reads its own keys
// (material_laws.cpp).
#include <fmt/format.h>
#include <toml++/toml.h>

#include "io/scenario/material_laws.hpp"
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
    // The law's own keys (material_laws.cpp).
    material_law(m.model).read(LawInput{t, w, key, errors_}, m);
    c.materials.push_back(std::move(m));
  }
}

}  // namespace crater::io::reader
