// Storage of an explicit Lagrangian solid: nodes and one element block (Q4 in 2D, Hex8 in 3D),
// structure of arrays, plus a structured mesh generator for rectangles and boxes.
//
// Units: SI. In 2D (plane strain) every extensive quantity is per metre of depth: element
// "volume" is an area x 1 m, masses kg/m, forces N/m.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/types.hpp"
#include "fem/element_geometry.hpp"
#include "fem/hourglass.hpp"
#include "materials/strength/stress_tensor.hpp"

namespace crater::fem {

/// Nodes, connectivity and element state of one element block.
template <int D>
struct ExplicitMesh {
  // ---- nodes (one entry per node)
  std::vector<Vec<D>> reference_position;  // X at t = 0 [m]
  std::vector<Vec<D>> position;            // x [m]
  std::vector<Vec<D>> velocity;            // v [m/s] (v^{n+1/2} during a step)
  std::vector<Vec<D>> internal_force;      // force of the elements ON the node [N]
  std::vector<Real> mass;                  // lumped mass [kg]
  // Mass scaling: the kinetic energy the node gave up taking mass, since t = 0 [J].
  std::vector<Real> mass_scaling_dissipated_j;

  // ---- elements (one entry per element)
  std::vector<ElementNodes<D>> elements;
  std::vector<materials::Mat3> stress;  // Cauchy stress, without bulk viscosity [Pa]
  std::vector<Real> plastic_strain;     // equivalent plastic strain [-]
  std::vector<Real> temperature_k;      // [K]
  std::vector<Real> damage;             // Johnson-Cook or HJC damage D [-]
  // Holmquist-Johnson-Cook compaction (HjcState; zero for the other laws):
  std::vector<Real> mu_max;                     // largest \mu = \rho/\rho_0 - 1 reached [-]
  std::vector<Real> plastic_volumetric_strain;  // \mu_p [-]
  std::vector<Real> reference_volume;           // V_0 [m^3]
  std::vector<Real> volume;                     // V [m^3] at the last force evaluation
  std::vector<Real> internal_energy_j;          // work of the stress and bulk viscosity [J]
  std::vector<Real> hourglass_energy_j;         // work of the hourglass forces [J]
  std::vector<HourglassState<D>> hourglass;     // stiffness-form generalised forces
  std::vector<std::uint8_t> eroded;             // 1 once the element has failed
  std::vector<Real> added_mass_kg;              // mass scaling: added to the element so far [kg]

  // ---- node -> (element, local node) adjacency, CSR in element order (set by initialise).
  // Entry = element * kElementNodes + local node. Forces are gathered per node in this fixed
  // order, so they are bit-identical for any thread count.
  std::vector<Index> node_entry_offsets;
  std::vector<Index> node_entries;
  // Per-element nodal forces, scratch of the force computation.
  std::vector<NodeArray<D>> element_force;

  [[nodiscard]] Index node_count() const { return static_cast<Index>(position.size()); }
  [[nodiscard]] Index element_count() const { return static_cast<Index>(elements.size()); }

  /// Nodal positions of element e.
  [[nodiscard]] NodeArray<D> element_positions(Index e) const {
    NodeArray<D> x;
    const auto& nodes = elements[static_cast<std::size_t>(e)];
    for (int i = 0; i < kElementNodes<D>; ++i) {
      x[i] = position[static_cast<std::size_t>(nodes[i])];
    }
    return x;
  }
  /// Nodal velocities of element e.
  [[nodiscard]] NodeArray<D> element_velocities(Index e) const {
    NodeArray<D> v;
    const auto& nodes = elements[static_cast<std::size_t>(e)];
    for (int i = 0; i < kElementNodes<D>; ++i) {
      v[i] = velocity[static_cast<std::size_t>(nodes[i])];
    }
    return v;
  }
};

/// A structured grid of cells[k] elements along each axis between corners lo and hi [m].
/// Node (i, j[, k]) has index i + (n_x + 1) (j + (n_y + 1) k). `distortion` moves every node
/// that is not on the boundary by a uniform random offset in [-distortion h_k, distortion h_k]
/// along each axis k (h_k the cell size; keep it below 0.25 so elements stay convex); `seed`
/// makes the offsets reproducible.
template <int D>
struct StructuredMeshSpec {
  Vec<D> lo = Vec<D>::Zero();
  Vec<D> hi = Vec<D>::Ones();
  std::array<Index, D> cells{};
  Real distortion = 0;
  std::uint64_t seed = 1;
};

/// Nodes and elements of the structured mesh (positions, connectivity; no state yet: call
/// initialise() of explicit_solid.hpp before use).
template <int D>
ExplicitMesh<D> structured_mesh(const StructuredMeshSpec<D>& spec);

/// Index of node (i, j[, k]) of a structured mesh with `cells` elements per axis.
template <int D>
inline Index structured_node_index(const std::array<Index, D>& cells,
                                   const std::array<Index, D>& ijk) {
  Index index = 0;
  for (int k = D - 1; k >= 0; --k) {
    index = index * (cells[k] + 1) + ijk[k];
  }
  return index;
}

}  // namespace crater::fem
