// The initial geostatic stress; see geostatic.hpp.
#include "fem/geostatic.hpp"

#include <spdlog/spdlog.h>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include "core/index.hpp"
#include "materials/strength/strength.hpp"

namespace crater::fem {

GeostaticParams geostatic_params(const GeostaticSettings& settings, int dimension,
                                 const parts::Vec3& gravity_m_s2, const SolidMaterial& material) {
  if (std::holds_alternative<materials::HolmquistJohnsonCookLaw>(material.strength))
    throw std::invalid_argument(
        "geostatic: not for Holmquist-Johnson-Cook (its pressure follows from the density)");
  GeostaticParams p;
  int axes = 0;
  for (int k = 0; k < dimension; ++k)
    if (gravity_m_s2[at(k)] != 0) {
      p.vertical_axis = k;
      ++axes;
    }
  if (axes != 1) throw std::invalid_argument("geostatic: gravity must act along exactly one axis");
  p.gravity_m_s2 = gravity_m_s2[at(p.vertical_axis)];
  p.surface_m = settings.surface_m;
  p.density_kg_m3 = material.density_kg_m3;
  p.k0 = settings.k0 ? *settings.k0
                     : at_rest_earth_pressure_coefficient(
                           materials::elastic_of(material.strength).poisson_ratio);
  return p;
}

template <int D>
GeostaticReport initialise_geostatic_stress(ExplicitMesh<D>& mesh, const SolidMaterial& material,
                                            const GeostaticParams& p) {
  constexpr int kNodes = kElementNodes<D>;
  GeostaticReport report;
  const materials::MaterialPointState at_start{.plastic_strain = 0,
                                               .temperature_k = material.initial_temperature_k};
  for (Index e = 0; e < mesh.element_count(); ++e) {
    Real coordinate_m = 0;
    for (Index n : mesh.elements[at(e)])
      coordinate_m += mesh.reference_position[at(n)][p.vertical_axis];
    coordinate_m /= Real(kNodes);
    const materials::Mat3 sigma = geostatic_stress(p, coordinate_m);
    mesh.stress[at(e)] = sigma;
    // The law's return with no strain increment: plastic strain means the state is outside
    // the yield surface, and the first step moves it onto it.
    const bool outside = std::visit(
        [&](const auto& law) {
          using Law = std::decay_t<decltype(law)>;
          if constexpr (std::is_same_v<Law, materials::HolmquistJohnsonCookLaw>) {
            return false;  // geostatic_params refuses it
          } else {
            return materials::update_stress_of(law, sigma, materials::Mat3::Zero(), at_start,
                                               Real(1), material.density_kg_m3)
                       .plastic_strain_increment > 0;
          }
        },
        material.strength);
    if (outside) {
      if (report.first_outside < 0) report.first_outside = e;
      ++report.outside_yield;
    }
  }
  return report;
}

template <int D>
void apply_geostatic_stress(ExplicitMesh<D>& mesh, const SolidMaterial& material,
                            const GeostaticSettings& settings, const parts::Vec3& gravity_m_s2,
                            const std::string& part_name) {
  const GeostaticParams p = geostatic_params(settings, D, gravity_m_s2, material);
  const GeostaticReport r = initialise_geostatic_stress(mesh, material, p);
  if (r.outside_yield > 0)
    spdlog::warn(
        "part '{}': the geostatic stress (K_0 = {}) of {} of its {} elements (the first: element "
        "{}) lies outside the material's yield surface; the first step returns it onto the "
        "surface with plastic flow, and the part is not at rest (the energy guard, "
        "time.energy_stop_error, may stop the run at its first step)",
        part_name, p.k0, r.outside_yield, mesh.element_count(), r.first_outside);
}

template GeostaticReport initialise_geostatic_stress<2>(ExplicitMesh<2>&, const SolidMaterial&,
                                                        const GeostaticParams&);
template GeostaticReport initialise_geostatic_stress<3>(ExplicitMesh<3>&, const SolidMaterial&,
                                                        const GeostaticParams&);
template void apply_geostatic_stress<2>(ExplicitMesh<2>&, const SolidMaterial&,
                                        const GeostaticSettings&, const parts::Vec3&,
                                        const std::string&);
template void apply_geostatic_stress<3>(ExplicitMesh<3>&, const SolidMaterial&,
                                        const GeostaticSettings&, const parts::Vec3&,
                                        const std::string&);

}  // namespace crater::fem
