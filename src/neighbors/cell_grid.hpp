// Uniform cell grid over the bounding box of a point set, used to bucket points for the
// neighbour search and to re-sort parts for memory locality.
//
// Correctness only needs cell_size >= search radius: then two points within the radius sit in
// the same or in adjacent cells. Coordinates are clamped into the grid, which turns the first and
// last cell of each axis into half-infinite slabs; the argument still holds, so query points
// outside the box (cross lists) need no special case.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "core/types.hpp"

namespace crater::neighbors {

template <int D>
struct GridSpec {
  /// Cell coordinates are floor((p - origin) / cell_size) - base. Normally origin is 0 and base
  /// the grid's first cell on the lattice of cells anchored at 0: the lattice cell of a point
  /// does not depend on the other points, so two point sets (the entities of two ranks) sorted
  /// with the same cell size put a point shared by both in the same lattice cell. Where the
  /// lattice index would not be exact (|p| / cell_size >= 2^52: far outliers, or a tiny cell),
  /// origin is the lowest point and base 0 instead.
  Vec<D> origin = Vec<D>::Zero();
  IVec<D> base = IVec<D>::Zero();
  /// Edge of a (square/cubic) cell; >= the requested size (see make_grid_spec).
  Real cell_size = 1;
  /// Number of cells per axis, each >= 1.
  IVec<D> dims = IVec<D>::Ones();

  Index cell_count() const { return dims.prod(); }

  /// Integer cell coordinates of p, clamped into the grid. p must be finite.
  IVec<D> cell_coords(const Vec<D>& p) const {
    IVec<D> c;
    for (int k = 0; k < D; ++k) {
      // Clamp in floating point first: a far-away query point must not overflow the cast.
      const Real t = std::floor((p[k] - origin[k]) / cell_size) - static_cast<Real>(base[k]);
      const Real top = static_cast<Real>(dims[k] - 1);
      c[k] = static_cast<Index>(std::clamp(t, Real(0), top));
    }
    return c;
  }

  /// Row-major linear cell index: the last axis varies fastest.
  Index linear(const IVec<D>& c) const {
    Index l = c[0];
    for (int k = 1; k < D; ++k) {
      l = l * dims[k] + c[k];
    }
    return l;
  }

  Index cell_index(const Vec<D>& p) const { return linear(cell_coords(p)); }
};

/// Grid covering the bounding box of x with cells of at least `cell_size`.
/// The cell size is enlarged by a relative 1e-6 so that rounding in cell_coords can never put two
/// points at distance exactly cell_size two cells apart, and enlarged further if the box would
/// need more than 4 * x.size() + 64 cells (memory guard; far outliers then make cells coarse).
/// The origin is the box minimum rounded down to a multiple of the cell size, so that the cell
/// faces do not move with the box.
/// Throws std::invalid_argument if cell_size is not positive and finite, if a coordinate is not
/// finite, or if the box extent overflows.
template <int D>
GridSpec<D> make_grid_spec(std::span<const Vec<D>> x, Real cell_size);

/// Permutation `order` such that x[order[0]], x[order[1]], ... are grouped by cell of
/// make_grid_spec(x, cell_size), cells in ascending linear index, and within a cell in
/// ascending `key` when one is given (each entity's global id), else in their original order
/// (stable counting sort). A part re-sorts its arrays with new[i] = old[order[i]].
///
/// With keys, the order of two entities depends only on their positions, keys and the grid's
/// cell size: cells follow the lattice anchored at 0 (GridSpec::base), and the lexicographic
/// order of lattice cells is the order of the linear index on any grid that holds both. So any
/// subset of the points (one rank's entities and ghosts) sorts into the restriction of the
/// whole set's order, and the neighbour lists built on it list each entity's partners in the
/// same order as on the whole set (docs/distributed.md). Where make_grid_spec's memory guard
/// would coarsen the cells (a sparse set), the points are sorted by their lattice cells of the
/// size asked for all the same (a comparison sort), so the order never depends on the set.
template <int D>
std::vector<Index> cell_sort_order(std::span<const Vec<D>> x, Real cell_size,
                                   std::span<const std::int64_t> key = {});

namespace detail {

/// Stable counting sort of x by cell of `grid`: on return order[s] is the original index of the
/// s-th point in cell order and the points of cell c are order[cell_start[c] .. cell_start[c+1]).
/// `cell` is scratch (cell index per point). Vectors keep their capacity across calls.
template <int D>
void bucket_by_cell(std::span<const Vec<D>> x, const GridSpec<D>& grid,
                    std::vector<Index>& cell_start, std::vector<Index>& order,
                    std::vector<Index>& cell);

}  // namespace detail

}  // namespace crater::neighbors
