// Where an FEM part's mesh comes from (a structured mesh of a box, or a mesh file) and the node
// sets its boundary conditions act on: a face of the mesh's bounding box, or a named group of
// the mesh file; with the boundary faces (segments in 2D, quadrilaterals in 3D) that lie in it.
#pragma once

#include <Eigen/Geometry>
#include <map>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "fem/explicit_mesh.hpp"
#include "fem/settings.hpp"
#include "mesh/gmsh.hpp"
#include "mesh/solid_mesh.hpp"

namespace crater::fem {

/// A face of the mesh boundary: its nodes, outward unit normal and area [m^2] (length x 1 m in
/// 2D), in the reference configuration.
template <int D>
struct BoundaryFace {
  std::vector<Index> nodes;
  Vec<D> unit_normal = Vec<D>::Zero();
  Real area = 0;
};

/// Nodes of a boundary condition, ascending, and the boundary faces made of them only.
template <int D>
struct NodeSet {
  std::vector<Index> nodes;
  int normal_axis = -1;  // the axis the set is a plane normal to, or -1
  std::vector<BoundaryFace<D>> faces;
};

/// The part's mesh (positions and connectivity) and its named node sets.
template <int D>
struct MeshSource {
  ExplicitMesh<D> mesh;
  std::map<std::string, NodeSet<D>> groups;
  Index reordered = 0;  // elements of a mesh file numbered the other way round (mirrored)
  /// The named group; throws std::runtime_error naming the known groups if there is none.
  const NodeSet<D>& group(const std::string& name) const;
};

/// Builds the mesh of an FEM part: the structured mesh of its box region (about spacing_m per
/// element, whole elements), or the elements of its mesh file.
template <int D>
MeshSource<D> build_mesh_source(const PartSettings& settings);

/// The part's mesh from its solid elements (mesh::solid_elements): elements numbered the other
/// way round are reordered (`reordered` counts them); every physical group becomes a node set
/// with its boundary faces. Throws InputError naming `file` and the line of a degenerate (zero
/// or twisted) element.
template <int D>
MeshSource<D> mesh_from_elements(const mesh::SolidElements& elements, const std::string& file,
                                 Index& reordered);

/// mesh_from_elements of mesh::solid_elements(gmsh, file, group, D): the elements of a Gmsh
/// file in one step (the fuzz target's way in).
template <int D>
MeshSource<D> mesh_from_gmsh(const mesh::GmshMesh& gmsh, const std::string& file,
                             const std::string& group, Index& reordered);

/// The nodes on a face of the mesh's bounding box (within 1e-9 of its extent).
template <int D>
NodeSet<D> face_node_set(const ExplicitMesh<D>& mesh, parts::Face face);

/// Area vector of a face in its node numbering's sense: (t_y, -t_x) x 1 m of depth in 2D,
/// (x_2 - x_0) x (x_3 - x_1) / 2 in 3D (exact for segments and planar quadrilaterals).
template <int D, class Nodes>
Vec<D> numbered_face_area(const std::vector<Vec<D>>& x, const Nodes& nodes) {
  if constexpr (D == 2) {
    const Vec<D> t = x[static_cast<std::size_t>(nodes[1])] - x[static_cast<std::size_t>(nodes[0])];
    return Vec<D>(t[1], -t[0]);
  } else {
    const Vec<D> d1 = x[static_cast<std::size_t>(nodes[2])] - x[static_cast<std::size_t>(nodes[0])];
    const Vec<D> d2 = x[static_cast<std::size_t>(nodes[3])] - x[static_cast<std::size_t>(nodes[1])];
    return Real(0.5) * d1.cross(d2);
  }
}

/// The surface of the live (not eroded) elements: faces no other live element shares, numbered
/// so that the outward normal is (t_y, -t_x), t = x_1 - x_0 (2D) or (x_2 - x_0) x (x_3 - x_1)
/// (3D), with the element of each and its area [m^2] (2D: length x 1 m), in the current
/// configuration; sorted by their node keys (deterministic).
template <int D>
struct SurfaceFaces {
  std::vector<std::array<Index, D == 2 ? 2 : 4>> nodes;
  std::vector<Index> element;
  std::vector<Real> area;            // in the current geometry [m^2; m per metre in 2D]
  std::vector<Real> reference_area;  // the same face at t = 0
};
template <int D>
SurfaceFaces<D> surface_faces(const ExplicitMesh<D>& mesh);

/// Every face of every element (live or not), sorted by its node key (ties in element, then
/// local face order), with where each run of one key ends: made once for a mesh's
/// connectivity, which erosion does not change, so that listing the surface again after an
/// erosion is a pass over the runs instead of a sort.
template <int D>
struct FaceIndex {
  std::vector<ElementNodes<D>> elements;     // the connectivity it was made for
  std::vector<std::pair<Index, int>> faces;  // (element, local face), by key
  std::vector<std::size_t> run_end;          // per run of equal keys, its end in `faces`
};
/// surface_faces of `mesh` through `index`, which is made again first if it was made for
/// another connectivity (or not yet); the one-argument form makes a fresh index.
template <int D>
SurfaceFaces<D> surface_faces(const ExplicitMesh<D>& mesh, FaceIndex<D>& index);

/// The boundary faces (faces of exactly one element) whose nodes are all in `sorted_nodes`.
template <int D>
std::vector<BoundaryFace<D>> boundary_faces_within(const ExplicitMesh<D>& mesh,
                                                   const std::vector<Index>& sorted_nodes);

}  // namespace crater::fem
