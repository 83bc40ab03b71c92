// Unit tests of the contact surface's listing (src/fem/fem_mesh_source.hpp): the faces of a box
// of hexahedra (quadrilaterals) counted by hand, intact and with an interior element eroded;
// and the listing through a FaceIndex made once for the connectivity, which must give the faces
// no other live face shares, in ascending key with their element (worked out here from a map of
// keys), and a fresh index's listing (nodes in their outward numbering, areas), after every
// round of erosion and motion, in 2D and 3D.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "core/index.hpp"
#include "fem/explicit_mesh.hpp"
#include "fem/fem_mesh_source.hpp"

namespace crater::fem {
namespace {

template <int D>
ExplicitMesh<D> box(const std::array<Index, D>& cells) {
  StructuredMeshSpec<D> spec;
  spec.cells = cells;
  spec.distortion = 0.1;
  spec.seed = 7;
  ExplicitMesh<D> mesh = structured_mesh<D>(spec);
  mesh.eroded.assign(at(mesh.element_count()), 0);
  return mesh;
}

// The faces of a quadrilateral and of a hexahedron by their local nodes (VTK numbering).
template <int D>
std::vector<std::vector<int>> faces_of_element() {
  if constexpr (D == 2)
    return {{0, 1}, {1, 2}, {2, 3}, {3, 0}};
  else
    return {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
}

// The surface worked out here on its own: every face of a live element keyed by its sorted
// nodes, those whose key no other live face has, in ascending key, with their element.
template <int D>
void expect_the_single_faces(const ExplicitMesh<D>& mesh, const SurfaceFaces<D>& listed) {
  std::map<std::vector<Index>, std::vector<Index>> elements_of;
  for (Index e = 0; e < mesh.element_count(); ++e) {
    if (mesh.eroded[at(e)]) continue;
    for (const auto& face : faces_of_element<D>()) {
      std::vector<Index> key;
      for (const auto local : face)
        key.push_back(mesh.elements[at(e)][at(local)]);
      std::sort(key.begin(), key.end());
      elements_of[key].push_back(e);
    }
  }
  std::vector<std::pair<std::vector<Index>, Index>> single;
  for (const auto& [key, elements] : elements_of)
    if (elements.size() == 1) single.emplace_back(key, elements.front());
  ASSERT_EQ(listed.nodes.size(), single.size());
  for (std::size_t f = 0; f < single.size(); ++f) {
    std::vector<Index> key(listed.nodes[f].begin(), listed.nodes[f].end());
    std::sort(key.begin(), key.end());
    EXPECT_EQ(key, single[f].first) << "face " << f;
    EXPECT_EQ(listed.element[f], single[f].second) << "face " << f;
  }
}

template <int D>
void expect_same(const SurfaceFaces<D>& fresh, const SurfaceFaces<D>& indexed) {
  ASSERT_EQ(fresh.nodes.size(), indexed.nodes.size());
  for (std::size_t f = 0; f < fresh.nodes.size(); ++f) {
    EXPECT_EQ(fresh.nodes[f], indexed.nodes[f]) << "face " << f;
    EXPECT_EQ(fresh.element[f], indexed.element[f]) << "face " << f;
    EXPECT_EQ(fresh.area[f], indexed.area[f]) << "face " << f;
    EXPECT_EQ(fresh.reference_area[f], indexed.reference_area[f]) << "face " << f;
  }
}

TEST(FemSurfaceFaces, ABoxHasItsOuterFacesAndAnErodedElementUncoversItsSix) {
  ExplicitMesh<3> mesh = box<3>({4, 3, 5});
  FaceIndex<3> index;
  // 2 (ab + bc + ca) faces on the outside of a 4 x 3 x 5 box.
  EXPECT_EQ(surface_faces(mesh).nodes.size(), 2u * (4 * 3 + 3 * 5 + 5 * 4));
  EXPECT_EQ(surface_faces(mesh, index).nodes.size(), 94u);
  // Element (1, 1, 2) lies inside: eroding it uncovers the six faces of its neighbours.
  mesh.eroded[at(1 + 4 * (1 + 3 * 2))] = 1;
  EXPECT_EQ(surface_faces(mesh).nodes.size(), 100u);
  EXPECT_EQ(surface_faces(mesh, index).nodes.size(), 100u);
  // 2D: 2 (a + b) edges of a 6 x 4 rectangle; an interior element uncovers four.
  ExplicitMesh<2> rect = box<2>({6, 4});
  FaceIndex<2> index2;
  EXPECT_EQ(surface_faces(rect, index2).nodes.size(), 20u);
  rect.eroded[at(2 + 6 * 1)] = 1;
  EXPECT_EQ(surface_faces(rect, index2).nodes.size(), 24u);
}

template <int D>
void check_rounds_of_erosion(const std::array<Index, D>& cells) {
  ExplicitMesh<D> mesh = box<D>(cells);
  FaceIndex<D> index;
  std::mt19937_64 rng(42 + D);
  std::uniform_real_distribution<Real> u(0, 1);
  for (int round = 0; round < 12; ++round) {
    SCOPED_TRACE(::testing::Message() << "D=" << D << " round " << round);
    const SurfaceFaces<D> kept = surface_faces(mesh, index);
    expect_the_single_faces<D>(mesh, kept);
    expect_same<D>(surface_faces(mesh), kept);
    // Some elements fail, and every node moves (the outward numbering follows the positions).
    for (auto& e : mesh.eroded)
      if (u(rng) < 0.06) e = 1;
    for (auto& x : mesh.position)
      for (int k = 0; k < D; ++k)
        x[k] += 0.02 * (u(rng) - 0.5);
  }
  // Everything eroded: no surface.
  mesh.eroded.assign(mesh.eroded.size(), 1);
  EXPECT_TRUE(surface_faces(mesh, index).nodes.empty());
  // Another connectivity (the elements renumbered): the index is made again.
  ExplicitMesh<D> other = box<D>(cells);
  std::reverse(other.elements.begin(), other.elements.end());
  other.eroded[0] = 1;
  expect_the_single_faces<D>(other, surface_faces(other, index));
}

TEST(FemSurfaceFaces, AnIndexMadeOnceListsTheFacesOfAFreshListingThroughErosion2D) {
  check_rounds_of_erosion<2>({9, 7});
}

TEST(FemSurfaceFaces, AnIndexMadeOnceListsTheFacesOfAFreshListingThroughErosion3D) {
  check_rounds_of_erosion<3>({5, 4, 6});
}

}  // namespace
}  // namespace crater::fem
