// A box of polydisperse grains, a touching lattice in its lower half agitated at 6 m/s per
// component (restitution 0.9), with friction, rolling resistance, gravity and walls on every
// face: the block bursts into the empty half, so the grains cross any cut again and again and
// the neighbour lists are built anew and the grains re-sorted many times. Shared by the DEM
// tests that need a bed in violent motion (tests/mpi/test_dem_ranks.cpp,
// tests/unit/dem/test_contact_handover.cpp).
#pragma once

#include <string>

namespace crater::test {

/// The scenario text: 3D, 6 x 12 x 6 lattice sites in a 3.6 x 7.2 x 3.6 cm box (the lattice
/// in its lower half); 2D, 16 x 24 in 6.4 x 9.6 cm.
inline std::string bursting_bed_scenario(int dim, const std::string& name) {
  const bool three = dim == 3;
  std::string s = "[scenario]\nname = \"" + name + "\"\ndimension = " + std::to_string(dim) +
                  "\nend_time_s = 1.0\n\n[domain]\n";
  s += three ? "min_m = [0.0, 0.0, 0.0]\nmax_m = [0.054, 0.108, 0.054]\n"
               "gravity_m_s2 = [0.0, -9.81, 0.0]\n"
             : "min_m = [0.0, 0.0]\nmax_m = [0.144, 0.216]\ngravity_m_s2 = [0.0, -9.81]\n";
  s += R"(
[[materials]]
name = "sand"
model = "granular"
rho0_kg_m3 = 2650.0
shear_modulus_pa = 2.0e8
poisson_ratio = 0.25
friction = 0.5
restitution = 0.9

[[parts]]
name = "bed"
method = "dem"
material = "sand"
spacing_m = 0.006
)";
  s += three ? "region = { type = \"box\", min_m = [0.0, 0.0, 0.0], max_m = [0.054, 0.054, "
               "0.054] }\n"
             : "region = { type = \"box\", min_m = [0.0, 0.0], max_m = [0.144, 0.108] }\n";
  s += R"(
[parts.dem]
radius_min_m = 0.0021
radius_max_m = 0.0029
rolling_friction = 0.1
local_damping = 0.0
)";
  s += three ? "walls = [\"left\", \"right\", \"bottom\", \"top\", \"back\", \"front\"]\n"
             : "walls = [\"left\", \"right\", \"bottom\", \"top\"]\n";
  s += "\n[parts.packing]\nagitation_m_s = 6.0\n";
  return s;
}

}  // namespace crater::test
