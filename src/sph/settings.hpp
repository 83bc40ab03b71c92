// Settings of an SPH part ([parts.sph] and its material), as the scenario reader builds them:
// plain values, no strings from the file. The solver's assembly hands a PartSettings to
// make_sph_part (sph_part.hpp).
// Defaults are the schema's (io/scenario/scenario_schema.cpp), stated nowhere else: members
// are only zero-initialised (tests/io/test_defaults_once.py).
#pragma once

#include <vector>

#include "core/types.hpp"
#include "materials/eos/eos.hpp"
#include "parts/setup.hpp"

namespace crater::sph {

/// Which kernel a scenario selects; the part maps it once to a kernel type (kernels.hpp).
enum class KernelKind { WendlandC2, CubicSpline };

/// How an SPH part gets its density: integrated from the continuity equation (eq. 32), or summed
/// over the neighbours' masses at each force stage with h iterated to match (sph_rates.cpp).
enum class DensityKind { Continuity, Summation };

/// Numerics of an SPH part ([parts.sph]).
struct Settings {
  KernelKind kernel{};
  DensityKind density{};
  Real h_factor{};
  Real av_alpha{};
  Real av_beta{};
  Real cfl{};
  bool variable_h{};
  Real xsph_epsilon{};
  Real tensile_epsilon{};
  Real viscosity_pa_s{};
  Real conductivity_alpha{};
  std::vector<parts::Face> walls;
  int wall_layers{};
  bool wall_no_slip{};
};

/// Everything an SPH part is built from.
struct PartSettings {
  parts::PartSetup part;
  Settings sph;
  materials::EosParams eos;
  Real rho0_kg_m3{};  // the material's reference density
};

}  // namespace crater::sph
