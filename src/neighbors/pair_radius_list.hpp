// Neighbour lists with a radius per point (SPH with variable h), on top of the fixed-radius
// cross lists of neighbor_list.hpp.
#pragma once

#include <span>
#include <vector>

#include "core/types.hpp"
#include "neighbors/neighbor_list.hpp"

namespace crater::neighbors {

/// For each i, all j != i with |x_i - x_j| <= max(reach[i], reach[j]) (squared distances
/// compared), ascending: the pairs either point's own radius takes in, for a set whose radii
/// differ (SPH with variable h: one list radius for all would let a few hot particles' supports
/// set every particle's list). The points are put in levels of doubling radius; each level is
/// searched at its own radius against the points of its level and below (cross lists), so a
/// point meets the few large-radius points near it without scanning the dense small-radius
/// points at their radius. Deterministic for any thread count; `scratch` keeps its capacity.
/// Same errors as build_neighbor_list (a radius not positive and finite).
template <int D>
void build_pair_radius_list(std::span<const Vec<D>> x, std::span<const Real> reach,
                            NeighborList& out, std::vector<NeighborList>& scratch);

/// For each point i of a, the points j of b with |a_i - b_j| <= max(reach_a[i], reach_b[j]),
/// ascending: the same levels and search between two sets (SPH: the fluid against its mirror
/// images, each image with its parent's radius). Throws std::invalid_argument when a radius is
/// not positive and finite or the radii do not match the points.
template <int D>
void build_cross_radius_list(std::span<const Vec<D>> a, std::span<const Real> reach_a,
                             std::span<const Vec<D>> b, std::span<const Real> reach_b,
                             NeighborList& out, std::vector<NeighborList>& scratch);

}  // namespace crater::neighbors
