// Fixed-radius neighbour lists by cell list, 2D and 3D, OpenMP-parallel.
//
// Results are identical for any thread count: each point's list depends only on the input, the
// list lengths are counted first, turned into offsets by a prefix sum, then filled in place.
// Every list is in ascending index order, so force loops over it sum in a fixed order.
//
// Fastest when the points were re-sorted with cell_sort_order (cell_grid.hpp) at a cell size
// equal to the radius: the candidates are then scanned in place. In any order the result is
// the same, only slower (3-4x for random order, see bench/bench_neighbors.cpp).
//
// Scratch memory (bucketed copy of the points, distance masks) is kept per thread between
// calls, a few tens of bytes per point of the largest set seen; calls from different threads
// do not share it.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "core/types.hpp"

namespace crater::neighbors {

/// Neighbour lists in compressed-row form: the neighbours of point i are
/// indices[offsets[i] .. offsets[i+1]), ascending.
struct NeighborList {
  std::vector<Index> offsets;  // size() + 1 entries, offsets[0] == 0
  std::vector<Index> indices;

  /// Number of query points (rows).
  Index size() const { return offsets.empty() ? 0 : static_cast<Index>(offsets.size()) - 1; }

  std::span<const Index> of(Index i) const {
    const auto b = static_cast<std::size_t>(offsets[static_cast<std::size_t>(i)]);
    const auto e = static_cast<std::size_t>(offsets[static_cast<std::size_t>(i) + 1]);
    return {indices.data() + b, e - b};
  }

  /// Number of stored (i, j) entries: each pair twice in Pairs::Full, once in Pairs::Half.
  Index total_pairs() const { return static_cast<Index>(indices.size()); }
};

enum class Pairs {
  Full,  // every j != i within the radius
  Half,  // only j > i (each pair once)
};

/// For each i, all j != i with |x_i - x_j| <= radius (squared distances compared), ascending.
/// `out` keeps its capacity across calls, so a rebuild of similar size does not allocate.
/// Throws std::invalid_argument if radius is not positive and finite or a coordinate is not
/// finite (the message names the point index).
template <int D>
void build_neighbor_list(std::span<const Vec<D>> x, Real radius, Pairs mode, NeighborList& out);

/// For each point of a, the indices of the points of b with |a_i - b_j| <= radius, ascending.
/// Either set may be empty. Same errors as build_neighbor_list.
template <int D>
void build_cross_list(std::span<const Vec<D>> a, std::span<const Vec<D>> b, Real radius,
                      NeighborList& out);

/// A fixed set b bucketed once for many cross searches at one radius (a kept candidate list
/// searching a few points again, step after step, against the set as it was at its build):
/// query(a) gives build_cross_list(a, b, radius)'s list, without bucketing b again.
template <int D>
class CrossIndex {
 public:
  CrossIndex();
  ~CrossIndex();
  CrossIndex(CrossIndex&&) noexcept;
  CrossIndex& operator=(CrossIndex&&) noexcept;

  /// Buckets b for searches within `radius` (build_cross_list's errors). b is copied.
  void build(std::span<const Vec<D>> b, Real radius);
  /// Whether build() has been called since the last clear().
  bool built() const { return built_; }
  void clear() { built_ = false; }
  /// For each point of a, the points of b within the radius, ascending (a's points must be
  /// finite: the errors of build_cross_list).
  void query(std::span<const Vec<D>> a, NeighborList& out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  bool built_ = false;
};

}  // namespace crater::neighbors
