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
#include <span>
#include <vector>

#include "core/types.hpp"

namespace crater::neighbors {

template <int D>
struct GridSpec {
  Vec<D> origin = Vec<D>::Zero();
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
      const Real t = (p[k] - origin[k]) / cell_size;
      const Real top = static_cast<Real>(dims[k] - 1);
      c[k] = static_cast<Index>(std::clamp(std::floor(t), Real(0), top));
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
/// make_grid_spec(x, cell_size), cells in ascending linear index, original order kept within a
/// cell (stable counting sort). A part re-sorts its arrays with new[i] = old[order[i]].
template <int D>
std::vector<Index> cell_sort_order(std::span<const Vec<D>> x, Real cell_size);

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
