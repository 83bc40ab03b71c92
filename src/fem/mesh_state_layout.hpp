// The part of an FEM part's checkpoint that is its mesh's state: one list of the vectors, in
// their order, for both directions (FemPart::save_state and load_state in fem_part.cpp), so
// a field added to ExplicitMesh is saved and loaded in one place.
#pragma once

#include "fem/explicit_mesh.hpp"

namespace crater::fem {

/// Which entities a saved vector has an entry per.
enum class MeshEntity { node, element };

/// Calls each(vector, entity, what it holds) for every saved vector of `mesh` (an
/// ExplicitMesh<D>, const for saving): nodes and elements as the checkpoint layout has them,
/// then, for a Holmquist-Johnson-Cook part (`compaction`), \mu_{max} and \mu_p. The other laws'
/// checkpoints stay as they were.
template <class Mesh, class Each>
void for_each_mesh_state_vector(Mesh& mesh, bool compaction, Each&& each) {
  constexpr MeshEntity node = MeshEntity::node, element = MeshEntity::element;
  each(mesh.position, node, "positions");
  each(mesh.velocity, node, "velocities");
  each(mesh.internal_force, node, "forces");
  each(mesh.mass, node, "masses");
  each(mesh.mass_scaling_dissipated_j, node, "kinetic energies given up to mass scaling");
  each(mesh.stress, element, "stresses");
  each(mesh.plastic_strain, element, "plastic strains");
  each(mesh.temperature_k, element, "temperatures");
  each(mesh.damage, element, "damage");
  each(mesh.volume, element, "volumes");
  each(mesh.internal_energy_j, element, "internal energies");
  each(mesh.hourglass_energy_j, element, "hourglass energies");
  each(mesh.hourglass, element, "hourglass forces");
  // An element failing next books the work of its last forces (explicit_solid.cpp).
  each(mesh.element_force, element, "element forces");
  each(mesh.eroded, element, "erosion flags");
  each(mesh.added_mass_kg, element, "added masses");
  if (compaction) {
    each(mesh.mu_max, element, "HJC largest compressions");
    each(mesh.plastic_volumetric_strain, element, "HJC plastic volumetric strains");
  }
}

}  // namespace crater::fem
