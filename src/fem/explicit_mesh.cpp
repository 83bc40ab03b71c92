// Structured mesh generator; see explicit_mesh.hpp.
#include "fem/explicit_mesh.hpp"

#include <random>
#include <stdexcept>

#include "core/index.hpp"

namespace crater::fem {

template <int D>
ExplicitMesh<D> structured_mesh(const StructuredMeshSpec<D>& spec) {
  ExplicitMesh<D> mesh;
  std::array<Index, D> nodes_per_axis;
  Index nn = 1;
  Index ne = 1;
  Vec<D> h;
  for (int k = 0; k < D; ++k) {
    if (spec.cells[at(k)] < 1) {
      throw std::invalid_argument("fem::structured_mesh: every axis needs at least one cell");
    }
    nodes_per_axis[at(k)] = spec.cells[at(k)] + 1;
    nn *= nodes_per_axis[at(k)];
    ne *= spec.cells[at(k)];
    h[k] = (spec.hi[k] - spec.lo[k]) / Real(spec.cells[at(k)]);
  }
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<Real> offset(-spec.distortion, spec.distortion);
  mesh.position.resize(at(nn));
  for (Index n = 0; n < nn; ++n) {
    std::array<Index, D> ijk;
    Index rest = n;
    bool boundary = false;
    for (int k = 0; k < D; ++k) {
      ijk[at(k)] = rest % nodes_per_axis[at(k)];
      rest /= nodes_per_axis[at(k)];
      boundary = boundary || ijk[at(k)] == 0 || ijk[at(k)] == spec.cells[at(k)];
    }
    Vec<D> x;
    for (int k = 0; k < D; ++k) {
      x[k] = spec.lo[k] + h[k] * Real(ijk[at(k)]);
    }
    if (spec.distortion > 0 && !boundary) {
      for (int k = 0; k < D; ++k) {
        x[k] += h[k] * offset(rng);
      }
    }
    mesh.position[at(n)] = x;
  }
  mesh.reference_position = mesh.position;
  mesh.elements.resize(at(ne));
  for (Index e = 0; e < ne; ++e) {
    std::array<Index, D> ijk;
    Index rest = e;
    for (int k = 0; k < D; ++k) {
      ijk[at(k)] = rest % spec.cells[at(k)];
      rest /= spec.cells[at(k)];
    }
    ElementNodes<D>& nodes = mesh.elements[at(e)];
    for (int local = 0; local < kElementNodes<D>; ++local) {
      std::array<Index, D> corner = ijk;
      for (int k = 0; k < D; ++k) {
        if (reference_sign<D>(local, k) > 0) {
          ++corner[at(k)];
        }
      }
      nodes[at(local)] = structured_node_index<D>(spec.cells, corner);
    }
  }
  return mesh;
}

template ExplicitMesh<2> structured_mesh<2>(const StructuredMeshSpec<2>&);
template ExplicitMesh<3> structured_mesh<3>(const StructuredMeshSpec<3>&);

}  // namespace crater::fem
