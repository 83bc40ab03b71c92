// The solid elements of a part in a Gmsh mesh; see solid_mesh.hpp.
#include "mesh/solid_mesh.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <limits>

#include "core/error.hpp"

namespace crater::mesh {

SolidElements solid_elements(const GmshMesh& gmsh, const std::string& file,
                             const std::string& group, int dimension) {
  const int wanted_type = dimension == 2 ? 3 : 5;  // quadrangle, hexahedron
  const char* wanted = dimension == 2 ? "4-node quadrangles" : "8-node hexahedra";
  auto fail = [&](int line, const std::string& what) {
    throw InputError({file, line, 0}, "", what);
  };
  // The part's elements: blocks of the scenario's dimension (of the named group).
  std::vector<const GmshMesh::Block*> blocks;
  bool group_seen = false;
  for (const auto& b : gmsh.blocks) {
    if (b.dim != dimension) continue;
    if (!group.empty() && b.physical_name != group) continue;
    group_seen = true;
    if (b.gmsh_type != wanted_type)
      fail(b.source_lines.empty() ? 0 : b.source_lines.front(),
           fmt::format("the part's elements must be {}; this {} has {} (Gmsh: "
                       "Mesh.RecombineAll = 1{} and Mesh.ElementOrder = 1)",
                       wanted, group.empty() ? "mesh" : "group '" + group + "'",
                       b.gmsh_type == 2   ? "triangles"
                       : b.gmsh_type == 4 ? "tetrahedra"
                                          : "other elements",
                       dimension == 3 ? " with a transfinite or extruded volume" : ""));
    blocks.push_back(&b);
  }
  if (blocks.empty()) {
    std::string known;
    for (const auto& b : gmsh.blocks)
      if (b.dim == dimension && !b.physical_name.empty())
        known += (known.empty() ? "'" : ", '") + b.physical_name + "'";
    fail(0, group.empty() || !group_seen
                ? fmt::format("no {} {}{} in the mesh (groups of dimension {}: {})", wanted,
                              group.empty() ? "" : "in group '", group.empty() ? "" : group + "'",
                              dimension, known.empty() ? "none" : known)
                : "no elements");
  }

  // Nodes the part uses, in file order.
  SolidElements out;
  out.dimension = dimension;
  out.nodes_per_element = dimension == 2 ? 4 : 8;
  const std::size_t n_all = gmsh.nodes.size();
  std::vector<std::int64_t> new_index(n_all, -1);
  for (const auto* b : blocks)
    for (std::int64_t n : b->connectivity)
      new_index[static_cast<std::size_t>(n)] = 0;
  for (std::size_t n = 0; n < n_all; ++n) {
    if (new_index[n] < 0) continue;
    new_index[n] = static_cast<std::int64_t>(out.nodes.size());
    if (dimension == 2 && gmsh.nodes[n][2] != 0)
      fail(0, fmt::format("a 2D part needs a flat mesh in the plane z = 0; node {} has z = {}",
                          gmsh.node_tags[n], gmsh.nodes[n][2]));
    out.nodes.push_back(gmsh.nodes[n]);
  }
  for (const auto* b : blocks) {
    for (std::int64_t n : b->connectivity)
      out.connectivity.push_back(new_index[static_cast<std::size_t>(n)]);
    out.source_lines.insert(out.source_lines.end(), b->source_lines.begin(), b->source_lines.end());
  }

  // Every physical group is a node set (of the nodes the part uses).
  for (const auto& b : gmsh.blocks) {
    if (b.physical_name.empty()) continue;
    auto& list = out.groups[b.physical_name].nodes;
    for (std::int64_t n : b.connectivity)
      if (const std::int64_t k = new_index[static_cast<std::size_t>(n)]; k >= 0) list.push_back(k);
  }
  for (auto it = out.groups.begin(); it != out.groups.end();) {
    auto& list = it->second.nodes;
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    if (list.empty()) {
      it = out.groups.erase(it);
      continue;
    }
    // A plane normal to an axis: the set's extent along it is ~0.
    std::array<double, 3> lo, hi;
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    for (std::int64_t n : list)
      for (int k = 0; k < dimension; ++k) {
        const auto kk = static_cast<std::size_t>(k);
        lo[kk] = std::min(lo[kk], out.nodes[static_cast<std::size_t>(n)][kk]);
        hi[kk] = std::max(hi[kk], out.nodes[static_cast<std::size_t>(n)][kk]);
      }
    double largest = -std::numeric_limits<double>::infinity();
    for (int k = 0; k < dimension; ++k)
      largest =
          std::max(largest, hi[static_cast<std::size_t>(k)] - lo[static_cast<std::size_t>(k)]);
    for (int k = 0; k < dimension; ++k)
      if (hi[static_cast<std::size_t>(k)] - lo[static_cast<std::size_t>(k)] <= 1e-9 * largest)
        it->second.normal_axis = k;
    ++it;
  }

  for (int k = 0; k < dimension; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    out.lo[kk] = out.hi[kk] = out.nodes.front()[kk];
    for (const auto& q : out.nodes) {
      out.lo[kk] = std::min(out.lo[kk], q[kk]);
      out.hi[kk] = std::max(out.hi[kk], q[kk]);
    }
  }
  return out;
}

}  // namespace crater::mesh
