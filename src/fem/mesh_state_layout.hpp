// The part of an FEM part's checkpoint that is its mesh's state: one list of the vectors, in
// their order, for both directions (FemPart::save_state and load_state in fem_part.cpp), so
// a field added to ExplicitMesh is saved and loaded in one place.
#pragma once

#include <cstddef>

#include "fem/explicit_mesh.hpp"

namespace crater::fem {

/// Calls each(vector, entries it must have, what it holds) for every saved vector of `mesh`
/// (an ExplicitMesh<D>, const for saving): nodes and elements as the checkpoint layout has
/// them, then, for a Holmquist-Johnson-Cook part (`compaction`), \mu_{max} and \mu_p. The
/// other laws' checkpoints stay as they were. The entry counts are taken before any vector
/// is read.
template <class Mesh, class Each>
void for_each_mesh_state_vector(Mesh& mesh, bool compaction, Each&& each) {
  const std::size_t nn = mesh.position.size(), ne = mesh.elements.size();
  each(mesh.position, nn, "positions");
  each(mesh.velocity, nn, "velocities");
  each(mesh.internal_force, nn, "forces");
  each(mesh.mass, nn, "masses");
  each(mesh.stress, ne, "stresses");
  each(mesh.plastic_strain, ne, "plastic strains");
  each(mesh.temperature_k, ne, "temperatures");
  each(mesh.damage, ne, "damage");
  each(mesh.volume, ne, "volumes");
  each(mesh.internal_energy_j, ne, "internal energies");
  each(mesh.hourglass_energy_j, ne, "hourglass energies");
  each(mesh.hourglass, ne, "hourglass forces");
  // An element failing next books the work of its last forces (explicit_solid.cpp).
  each(mesh.element_force, ne, "element forces");
  each(mesh.eroded, ne, "erosion flags");
  each(mesh.added_mass_kg, ne, "added masses");
  if (compaction) {
    each(mesh.mu_max, ne, "HJC largest compressions");
    each(mesh.plastic_volumetric_strain, ne, "HJC plastic volumetric strains");
  }
}

}  // namespace crater::fem
