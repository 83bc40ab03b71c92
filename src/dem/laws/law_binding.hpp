// What a DEM part asks of a contact law, beyond the law itself (contact_force.hpp: Params,
// prepare, finish). A law answers these questions as static members of its type, next to its
// equations (hertz_mindlin.hpp, linear_spring.hpp), and one line of src/dem/contact_laws.hpp
// registers it; the part (src/dem/dem_part_impl.hpp) asks them through the registry, never by
// the law's name:
//
//   struct SomeLaw {
//     using Params = SomeParams;
//     ... prepare, finish (contact_force.hpp) ...
//     // The grain-grain and grain-wall parameters, from the part's settings and grains.
//     static LawPair<SomeLaw> part_laws(const Settings&, const GranularMaterial&);
//     // 2D: whether a disk stands for a row of spheres along the depth (dem_part_impl.hpp).
//     static bool row_of_spheres(const Settings&);
//     // The law's share of the part's stable step (LawStep).
//     static LawStep part_step(const LawStepQuery&);
//     // The bed's P-wave speed behind absorbing walls when the scenario gives none [m/s];
//     // nullopt: the law has no estimate (the reader then asks for one).
//     static std::optional<Real> p_wave_speed(const Settings&, const MeanGrain&);
//   };
#pragma once

#include <concepts>
#include <limits>
#include <optional>
#include <string>

#include "core/types.hpp"
#include "dem/settings.hpp"

namespace crater::dem {

/// The grain-grain and grain-wall parameters of one contact law.
template <class Law>
struct LawPair {
  using Type = Law;
  typename Law::Params grain, wall;
};

/// What the part knows when it asks a law for its stable step.
struct LawStepQuery {
  const Settings& dem;
  const GranularMaterial& grain;
  Real radius_min_m = 0;   // the smallest grain's radius
  Real density_kg_m3 = 0;  // the grains' density
};

/// A law's share of the part's stable step: a step of its own (with its reason), and a spring
/// stiffness for the part's f sqrt(m_min / k) limit, to which the bonds' stiffness adds.
struct LawStep {
  Real dt_s = std::numeric_limits<Real>::infinity();  // inf: none
  std::string reason;
  Real stiffness_n_m = 0;  // [N/m] (per metre of depth in 2D); 0: none
};

/// The mean grain of a part (the absorbing walls' estimate of the bed's wave speed).
struct MeanGrain {
  Real radius_m = 0;
  Real mass_kg = 0;
};

/// A contact law a DEM part can take (the questions of the file comment).
template <class Law>
concept PartContactLaw = requires(const Settings& dem, const GranularMaterial& grain,
                                  const LawStepQuery& query, const MeanGrain& mean) {
  typename Law::Params;
  { Law::part_laws(dem, grain) } -> std::same_as<LawPair<Law>>;
  { Law::row_of_spheres(dem) } -> std::same_as<bool>;
  { Law::part_step(query) } -> std::same_as<LawStep>;
  { Law::p_wave_speed(dem, mean) } -> std::same_as<std::optional<Real>>;
};

}  // namespace crater::dem
