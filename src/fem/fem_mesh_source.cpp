// Meshes and node sets of FEM parts; see fem_mesh_source.hpp.
#include "fem/fem_mesh_source.hpp"

#include <fmt/format.h>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>

#include "core/error.hpp"
#include "core/index.hpp"
#include "fem/element_geometry.hpp"
#include "parts/setup.hpp"

namespace crater::fem {
namespace {

/// Local node numbers of the faces of an element (VTK / Gmsh numbering).
template <int D>
const std::vector<std::vector<int>>& local_faces() {
  static const std::vector<std::vector<int>> q4 = {{0, 1}, {1, 2}, {2, 3}, {3, 0}};
  static const std::vector<std::vector<int>> hex8 = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                                     {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  if constexpr (D == 2) {
    return q4;
  } else {
    return hex8;
  }
}

/// Outward normal x area of a face of element e.
template <int D>
Vec<D> face_area_vector(const ExplicitMesh<D>& mesh, Index e, std::span<const Index> nodes,
                        const std::vector<Vec<D>>& x) {
  Vec<D> a = numbered_face_area<D>(x, nodes);
  // Orient it away from the element's centre.
  Vec<D> centre = Vec<D>::Zero(), face_centre = Vec<D>::Zero();
  for (Index n : mesh.elements[at(e)])
    centre += x[at(n)] / Real(kElementNodes<D>);
  for (Index n : nodes)
    face_centre += x[at(n)] / Real(nodes.size());
  if (a.dot(face_centre - centre) < 0) a = -a;
  return a;
}

}  // namespace

template <int D>
const NodeSet<D>& MeshSource<D>::group(const std::string& name) const {
  const auto it = groups.find(name);
  if (it != groups.end()) return it->second;
  std::string known;
  for (const auto& [n, s] : groups)
    known += (known.empty() ? "" : ", ") + n;
  throw std::runtime_error(
      fmt::format("no mesh group '{}' (the mesh has: {})", name, known.empty() ? "none" : known));
}

template <int D>
std::vector<BoundaryFace<D>> boundary_faces_within(const ExplicitMesh<D>& mesh,
                                                   const std::vector<Index>& sorted_nodes) {
  auto in_set = [&](Index n) {
    return std::binary_search(sorted_nodes.begin(), sorted_nodes.end(), n);
  };
  // Faces of elements whose nodes are all in the set, keyed by their sorted nodes; a face that
  // two elements share is interior.
  struct Candidate {
    std::array<Index, 4> key{};
    Index element = 0;
    int face = 0;
  };
  std::vector<Candidate> candidates;
  const auto& faces = local_faces<D>();
  for (Index e = 0; e < mesh.element_count(); ++e) {
    const auto& nodes = mesh.elements[at(e)];
    for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
      Candidate c;
      c.key.fill(-1);
      bool all = true;
      for (std::size_t k = 0; k < faces[at(f)].size(); ++k) {
        const Index n = nodes[at(faces[at(f)][k])];
        all = all && in_set(n);
        c.key[k] = n;
      }
      if (!all) continue;
      std::sort(c.key.begin(), c.key.end());  // unused entries (-1) sort first
      c.element = e;
      c.face = f;
      candidates.push_back(c);
    }
  }
  std::vector<std::size_t> order(candidates.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return candidates[a].key < candidates[b].key;
  });
  std::vector<BoundaryFace<D>> out;
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i + 1;
    while (j < order.size() && candidates[order[j]].key == candidates[order[i]].key)
      ++j;
    if (j == i + 1) {
      const Candidate& c = candidates[order[i]];
      BoundaryFace<D> bf;
      for (int local : faces[at(c.face)])
        bf.nodes.push_back(mesh.elements[at(c.element)][at(local)]);
      const Vec<D> a = face_area_vector(mesh, c.element, bf.nodes, mesh.reference_position);
      bf.area = a.norm();
      bf.unit_normal = bf.area > 0 ? Vec<D>(a / bf.area) : Vec<D>::Zero();
      out.push_back(std::move(bf));
    }
    i = j;
  }
  // In the order of the sorted face keys: deterministic.
  return out;
}

namespace {

// The sorted node key of local face f of element e.
template <int D>
std::array<Index, 4> face_key(const ExplicitMesh<D>& mesh, Index e, int f) {
  constexpr int kF = D == 2 ? 2 : 4;
  const auto& faces = local_faces<D>();
  std::array<Index, 4> key;
  key.fill(-1);
  for (int k = 0; k < kF; ++k)
    key[at(k)] = mesh.elements[at(e)][at(faces[at(f)][at(k)])];
  std::sort(key.begin(), key.end());
  return key;
}

// Face f of element e as a surface face: its nodes numbered outward, its element, its area now
// and at t = 0.
template <int D>
void add_surface_face(const ExplicitMesh<D>& mesh, Index e, int f, SurfaceFaces<D>& out) {
  constexpr int kF = D == 2 ? 2 : 4;
  const auto& faces = local_faces<D>();
  std::array<Index, kF> nodes;
  for (int k = 0; k < kF; ++k)
    nodes[at(k)] = mesh.elements[at(e)][at(faces[at(f)][at(k)])];
  const std::array<Index, kF> numbered = nodes;  // the element's order, before any reversal
  const Vec<D> outward = face_area_vector<D>(mesh, e, numbered, mesh.position);
  // The numbering's own normal, reversed when it points inward.
  const Vec<D> own = numbered_face_area<D>(mesh.position, nodes);
  if (own.dot(outward) < 0) {
    if constexpr (D == 2) {
      std::swap(nodes[0], nodes[1]);
    } else {
      std::swap(nodes[1], nodes[3]);
    }
  }
  out.nodes.push_back(nodes);
  out.element.push_back(e);
  out.area.push_back(outward.norm());
  out.reference_area.push_back(
      face_area_vector<D>(mesh, e, numbered, mesh.reference_position).norm());
}

bool live(const std::vector<std::uint8_t>& eroded, Index e) {
  return eroded.empty() || !eroded[at(e)];
}

}  // namespace

// A surface face is a run of one key with exactly one live face; the runs come in ascending
// key, so the surface is listed by key whichever faces have eroded.
template <int D>
SurfaceFaces<D> surface_faces(const ExplicitMesh<D>& mesh, FaceIndex<D>& index) {
  if (index.elements != mesh.elements) {
    const auto nf = static_cast<int>(local_faces<D>().size());
    std::vector<std::array<Index, 4>> keys;
    index.faces.clear();
    for (Index e = 0; e < mesh.element_count(); ++e)
      for (int f = 0; f < nf; ++f) {
        index.faces.emplace_back(e, f);
        keys.push_back(face_key(mesh, e, f));
      }
    std::vector<std::size_t> order(keys.size());
    for (std::size_t i = 0; i < order.size(); ++i)
      order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return keys[a] < keys[b]; });
    std::vector<std::pair<Index, int>> sorted(order.size());
    index.run_end.clear();
    for (std::size_t i = 0; i < order.size(); ++i) {
      sorted[i] = index.faces[order[i]];
      if (i + 1 == order.size() || keys[order[i + 1]] != keys[order[i]])
        index.run_end.push_back(i + 1);
    }
    index.faces = std::move(sorted);
    index.elements = mesh.elements;
  }
  SurfaceFaces<D> out;
  std::size_t begin = 0;
  for (const std::size_t end : index.run_end) {
    std::size_t found = end, count = 0;
    for (std::size_t i = begin; i < end && count < 2; ++i)
      if (live(mesh.eroded, index.faces[i].first)) {
        found = i;
        ++count;
      }
    if (count == 1)
      add_surface_face(mesh, index.faces[found].first, index.faces[found].second, out);
    begin = end;
  }
  return out;
}

template <int D>
SurfaceFaces<D> surface_faces(const ExplicitMesh<D>& mesh) {
  FaceIndex<D> index;
  return surface_faces(mesh, index);
}

template <int D>
NodeSet<D> face_node_set(const ExplicitMesh<D>& mesh, parts::Face face) {
  NodeSet<D> set;
  set.normal_axis = static_cast<int>(face) / 2;
  set.nodes = parts::points_on_face<D>(mesh.reference_position, face);
  set.faces = boundary_faces_within(mesh, set.nodes);
  return set;
}

template <int D>
MeshSource<D> mesh_from_elements(const mesh::SolidElements& elements, const std::string& file,
                                 Index& reordered) {
  constexpr int kNodes = kElementNodes<D>;
  MeshSource<D> source;
  ExplicitMesh<D>& mesh = source.mesh;
  for (const auto& q : elements.nodes) {
    Vec<D> x;
    for (int k = 0; k < D; ++k)
      x[k] = q[at(k)];
    mesh.position.push_back(x);
  }
  mesh.reference_position = mesh.position;

  reordered = 0;
  for (std::int64_t e = 0; e < elements.element_count(); ++e) {
    ElementNodes<D> nodes;
    for (int k = 0; k < kNodes; ++k)
      nodes[at(k)] =
          static_cast<Index>(elements.connectivity[static_cast<std::size_t>(e * kNodes + k)]);
    NodeArray<D> x;
    for (int k = 0; k < kNodes; ++k)
      x[at(k)] = mesh.position[at(nodes[at(k)])];
    Real v = uniform_strain_gradients<D>(x).volume;
    if (v < 0) {
      // Numbered the other way round (e.g. a surface whose normal is -z): mirror the order.
      if constexpr (D == 2) {
        std::swap(nodes[1], nodes[3]);
      } else {
        std::swap(nodes[1], nodes[3]);
        std::swap(nodes[5], nodes[7]);
      }
      for (int k = 0; k < kNodes; ++k)
        x[at(k)] = mesh.position[at(nodes[at(k)])];
      v = uniform_strain_gradients<D>(x).volume;
      ++reordered;
    }
    if (!(v > 0))
      throw InputError(
          {file, elements.source_lines[static_cast<std::size_t>(e)], 0}, "",
          "degenerate element (zero volume, or twisted: its nodes are not in Gmsh's order)");
    mesh.elements.push_back(nodes);
  }

  // Every physical group is a node set, with the boundary faces it holds.
  for (const auto& [name, group] : elements.groups) {
    NodeSet<D> set;
    set.nodes.assign(group.nodes.begin(), group.nodes.end());
    set.normal_axis = group.normal_axis;
    set.faces = boundary_faces_within(mesh, set.nodes);
    source.groups.emplace(name, std::move(set));
  }
  return source;
}

template <int D>
MeshSource<D> mesh_from_gmsh(const mesh::GmshMesh& gmsh, const std::string& file,
                             const std::string& group, Index& reordered) {
  return mesh_from_elements<D>(mesh::solid_elements(gmsh, file, group, D), file, reordered);
}

template <int D>
MeshSource<D> build_mesh_source(const PartSettings& settings) {
  const parts::PartSetup& part = settings.part;
  MeshSource<D> source;
  if (settings.fem.elements) {
    Index reordered = 0;
    source = mesh_from_elements<D>(*settings.fem.elements, settings.fem.mesh_file, reordered);
    source.reordered = reordered;
    return source;
  }
  StructuredMeshSpec<D> spec;
  for (int d = 0; d < D; ++d) {
    spec.lo[d] = part.region.min_m[at(d)];
    spec.hi[d] = part.region.max_m[at(d)];
    spec.cells[at(d)] = std::max<Index>(
        1, static_cast<Index>(std::llround((spec.hi[d] - spec.lo[d]) / part.spacing_m)));
  }
  source.mesh = structured_mesh<D>(spec);
  return source;
}

template MeshSource<2> mesh_from_elements<2>(const mesh::SolidElements&, const std::string&,
                                             Index&);
template MeshSource<3> mesh_from_elements<3>(const mesh::SolidElements&, const std::string&,
                                             Index&);
template MeshSource<2> mesh_from_gmsh<2>(const mesh::GmshMesh&, const std::string&,
                                         const std::string&, Index&);
template MeshSource<3> mesh_from_gmsh<3>(const mesh::GmshMesh&, const std::string&,
                                         const std::string&, Index&);
template struct MeshSource<2>;
template struct MeshSource<3>;
template MeshSource<2> build_mesh_source<2>(const PartSettings&);
template MeshSource<3> build_mesh_source<3>(const PartSettings&);
template SurfaceFaces<2> surface_faces<2>(const ExplicitMesh<2>&);
template SurfaceFaces<3> surface_faces<3>(const ExplicitMesh<3>&);
template SurfaceFaces<2> surface_faces<2>(const ExplicitMesh<2>&, FaceIndex<2>&);
template SurfaceFaces<3> surface_faces<3>(const ExplicitMesh<3>&, FaceIndex<3>&);
template NodeSet<2> face_node_set<2>(const ExplicitMesh<2>&, parts::Face);
template NodeSet<3> face_node_set<3>(const ExplicitMesh<3>&, parts::Face);
template std::vector<BoundaryFace<2>> boundary_faces_within<2>(const ExplicitMesh<2>&,
                                                               const std::vector<Index>&);
template std::vector<BoundaryFace<3>> boundary_faces_within<3>(const ExplicitMesh<3>&,
                                                               const std::vector<Index>&);

}  // namespace crater::fem
