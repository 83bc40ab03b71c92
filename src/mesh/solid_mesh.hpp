// The solid elements of one part in a Gmsh mesh: the 4-node quadrangles (2D) or 8-node
// hexahedra (3D) of one physical group, or of the whole mesh, with only the nodes they use,
// and every physical group as a set of those nodes. Taken from the file once, when the
// scenario is read: the reader checks the part against it (bounding box, groups) and the FEM
// part is built from it (fem::mesh_from_elements orients the elements and checks their shape).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "mesh/gmsh.hpp"

namespace crater::mesh {

struct SolidElements {
  int dimension = 0;
  /// The nodes the elements use, in the file's order (x, y, z; z = 0 in 2D).
  std::vector<std::array<double, 3>> nodes;
  int nodes_per_element = 0;  // 4 (2D) or 8 (3D)
  /// Indices into `nodes`, nodes_per_element per element, in Gmsh's node order.
  std::vector<std::int64_t> connectivity;
  std::vector<int> source_lines;  // the line of the file each element is on

  /// A physical group's nodes among `nodes` (ascending), and the axis (< dimension) along which
  /// they lie in one plane (extent within 1e-9 of their largest extent), or -1.
  struct Group {
    std::vector<std::int64_t> nodes;
    int normal_axis = -1;
  };
  std::map<std::string, Group> groups;  // groups with no node among `nodes` are left out

  std::array<double, 3> lo{}, hi{};  // bounding box of `nodes`

  std::int64_t element_count() const {
    return nodes_per_element > 0
               ? static_cast<std::int64_t>(connectivity.size()) / nodes_per_element
               : 0;
  }
};

/// The solid elements of `group` (empty: all) of a `dimension`-D part. Throws InputError naming
/// `file` (and the line of the element at fault): no such elements, triangles or tetrahedra
/// where the part's elements are, a 2D mesh that is not flat.
SolidElements solid_elements(const GmshMesh& gmsh, const std::string& file,
                             const std::string& group, int dimension);

}  // namespace crater::mesh
