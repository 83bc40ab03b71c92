// Settings of an SPH part ([parts.sph] and its material), as the scenario reader builds them:
// plain values, no strings from the file. The solver's assembly hands a PartSettings to
// make_sph_part (sph_part.hpp).
#pragma once

#include <vector>

#include "core/types.hpp"
#include "materials/eos/eos.hpp"
#include "parts/setup.hpp"

namespace crater::sph {

/// Which kernel a scenario selects; the part maps it once to a kernel type (kernels.hpp).
enum class KernelKind { WendlandC2, CubicSpline };

/// Numerics of an SPH part ([parts.sph]).
struct Settings {
  KernelKind kernel = KernelKind::WendlandC2;
  Real h_factor = 1.3;
  Real av_alpha = 1.0;
  Real av_beta = 2.0;
  Real cfl = 0.3;
  bool variable_h = true;
  Real xsph_epsilon = 0;
  Real tensile_epsilon = 0;
  Real viscosity_pa_s = 0;
  std::vector<parts::Face> walls;
  int wall_layers = 3;
  bool wall_no_slip = false;
};

/// Everything an SPH part is built from.
struct PartSettings {
  parts::PartSetup part;
  Settings sph;
  materials::EosParams eos;
  Real rho0_kg_m3 = 0;  // the material's reference density
};

}  // namespace crater::sph
