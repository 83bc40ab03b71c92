#include "neighbors/cell_grid.hpp"

#include <omp.h>

#include "parallel/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace crater::neighbors {

namespace {

// Relative enlargement of the cell: cell coordinates carry a rounding error of a few ulps of
// their magnitude (at most ~4e8 cells per axis here), far below this margin.
constexpr Real kCellMargin = 1e-6;

std::string to_string_g(Real v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

template <int D>
GridSpec<D> make_grid_spec(std::span<const Vec<D>> x, Real cell_size) {
  if (!(cell_size > 0) || !std::isfinite(cell_size)) {
    throw std::invalid_argument("cell grid: cell size must be positive and finite, got " +
                                to_string_g(cell_size));
  }
  const Index n = static_cast<Index>(x.size());
  GridSpec<D> g;
  g.cell_size = cell_size * (1 + kCellMargin);
  if (n == 0) return g;

  constexpr Real inf = std::numeric_limits<Real>::infinity();
  Vec<D> lo = Vec<D>::Constant(inf);
  Vec<D> hi = Vec<D>::Constant(-inf);
  Index bad = n;  // first point with a non-finite coordinate
#pragma omp parallel if (parallel::forks(n))
  {
    Vec<D> tlo = Vec<D>::Constant(inf);
    Vec<D> thi = Vec<D>::Constant(-inf);
    Index tbad = n;
#pragma omp for schedule(static) nowait
    for (Index i = 0; i < n; ++i) {
      const Vec<D>& p = x[static_cast<std::size_t>(i)];
      if (!p.allFinite()) {
        tbad = std::min(tbad, i);
        continue;
      }
      tlo = tlo.cwiseMin(p);
      thi = thi.cwiseMax(p);
    }
    // min/max are exact, so the merge order does not matter.
#pragma omp critical(crater_neighbors_bbox)
    {
      lo = lo.cwiseMin(tlo);
      hi = hi.cwiseMax(thi);
      bad = std::min(bad, tbad);
    }
  }
  if (bad < n) {
    throw std::invalid_argument("cell grid: non-finite coordinate at point " + std::to_string(bad));
  }
  const Vec<D> extent = hi - lo;
  if (!extent.allFinite()) {
    throw std::invalid_argument("cell grid: coordinate range overflows double");
  }

  // Memory guard: at most `cap` cells. Bounding each axis first keeps the product finite; the
  // "+ 2" allows for the origin snapping below.
  const Real cap = 4.0 * static_cast<Real>(n) + 64.0;
  Real h = std::max(g.cell_size, extent.maxCoeff() / cap);
  const auto cells_for = [&extent](Real size) {
    Real prod = 1;
    for (int k = 0; k < D; ++k) {
      prod *= std::floor(extent[k] / size) + 2;
    }
    return prod;
  };
  for (Real prod = cells_for(h); prod > cap; prod = cells_for(h)) {
    h *= std::max(Real(1.01), std::pow(prod / cap, Real(1) / D));
  }
  g.cell_size = h;

  // Cells are those of the lattice anchored at 0 (GridSpec::base), so cell faces stay fixed in
  // space while the box moves: between two re-sorts a point changes cell only by crossing a
  // face, and a part sorted by cell_sort_order stays (nearly) in cell order. The expressions are
  // cell_coords', so that the lowest and the highest point land in the first and the last cell.
  for (int k = 0; k < D; ++k) {
    Real first = std::floor(lo[k] / h);
    Real last = std::floor(hi[k] / h);
    if (!(std::abs(first) < 0x1p52 && std::abs(last) < 0x1p52)) {
      g.origin[k] = lo[k];  // the lattice index would not be exact: cells from the lowest point
      first = 0;
      last = std::floor((hi[k] - lo[k]) / h);
    }
    g.base[k] = static_cast<Index>(first);
    g.dims[k] = static_cast<Index>(last - first) + 1;
  }
  return g;
}

namespace detail {

template <int D>
void bucket_by_cell(std::span<const Vec<D>> x, const GridSpec<D>& grid,
                    std::vector<Index>& cell_start, std::vector<Index>& order,
                    std::vector<Index>& cell) {
  const Index n = static_cast<Index>(x.size());
  const Index ncell = grid.cell_count();
  cell.resize(static_cast<std::size_t>(n));
  order.resize(static_cast<std::size_t>(n));
  cell_start.resize(static_cast<std::size_t>(ncell + 1));
  Index* start = cell_start.data();
  parallel::for_each(ncell + 1, [&](Index c) { start[c] = 0; });
  parallel::for_each(n, [&](Index i) {
    cell[static_cast<std::size_t>(i)] = grid.cell_index(x[static_cast<std::size_t>(i)]);
  });
  // Counting sort: each cell's count at its own entry, their running sum (the end of each
  // cell; in blocks of cells, in parallel: a sparse bed's grid has many more cells than
  // points), then the points scattered backwards from each end, so that each entry ends at its
  // cell's start and each cell holds its points ascending.
  const Index* ci = cell.data();
  for (Index i = 0; i < n; ++i) {
    ++start[ci[i]];
  }
  constexpr Index kScanBlock = 4096;
  const Index blocks = (ncell + 1 + kScanBlock - 1) / kScanBlock;
  std::vector<Index> before(static_cast<std::size_t>(blocks) + 1, 0);
  parallel::for_each_block(ncell + 1, kScanBlock, [&](Index first, Index last) {
    Index sum = 0;
    for (Index c = first; c < last; ++c)
      sum += start[c];
    before[static_cast<std::size_t>(first / kScanBlock) + 1] = sum;
  });
  for (std::size_t b = 0; b < static_cast<std::size_t>(blocks); ++b)
    before[b + 1] += before[b];
  parallel::for_each_block(ncell + 1, kScanBlock, [&](Index first, Index last) {
    Index sum = before[static_cast<std::size_t>(first / kScanBlock)];
    for (Index c = first; c < last; ++c) {
      sum += start[c];
      start[c] = sum;
    }
  });
  Index* ord = order.data();
  for (Index i = n - 1; i >= 0; --i) {
    ord[--start[ci[i]]] = i;
  }
}

}  // namespace detail

template <int D>
std::vector<Index> cell_sort_order(std::span<const Vec<D>> x, Real cell_size,
                                   std::span<const std::int64_t> key) {
  if (!key.empty() && key.size() != x.size())
    throw std::invalid_argument("cell_sort_order: one key per point expected");
  const GridSpec<D> grid = make_grid_spec<D>(x, cell_size);
  const Real h = cell_size * (1 + kCellMargin);
  if (grid.cell_size != h && grid.origin.isZero()) {
    // The memory guard coarsened the grid (a sparse set: an expanding charge). Its cells would
    // depend on the set's extent and count, so the order of a subset (a rank's particles) would
    // not be that of the whole set: sort by the lattice cells of the size asked for, in the
    // counting sort's order (first axis slowest), without a dense grid.
    const std::size_t n = x.size();
    std::vector<Real> cells(n * D);
    parallel::for_each(static_cast<Index>(n), [&](Index i) {
      for (int k = 0; k < D; ++k)
        cells[static_cast<std::size_t>(i) * D + static_cast<std::size_t>(k)] =
            std::floor(x[static_cast<std::size_t>(i)][k] / h);
    });
    std::vector<Index> order(n);
    std::iota(order.begin(), order.end(), Index{0});
    std::sort(order.begin(), order.end(), [&](Index a, Index b) {
      const Real* ca = &cells[static_cast<std::size_t>(a) * D];
      const Real* cb = &cells[static_cast<std::size_t>(b) * D];
      for (int k = 0; k < D; ++k)
        if (ca[k] != cb[k]) return ca[k] < cb[k];
      if (!key.empty()) return key[static_cast<std::size_t>(a)] < key[static_cast<std::size_t>(b)];
      return a < b;
    });
    return order;
  }
  std::vector<Index> cell_start;
  std::vector<Index> order;
  std::vector<Index> cell;
  detail::bucket_by_cell<D>(x, grid, cell_start, order, cell);
  if (!key.empty()) {
    // Each cell's few points by key (a grain's cell holds a handful).
    const Index ncell = grid.cell_count();
    parallel::for_each_block(ncell, 256, [&](Index first, Index last) {
      for (Index c = first; c < last; ++c) {
        const auto b = order.begin() + cell_start[static_cast<std::size_t>(c)];
        const auto e = order.begin() + cell_start[static_cast<std::size_t>(c) + 1];
        if (e - b > 1)
          std::sort(b, e, [&](Index i, Index j) {
            return key[static_cast<std::size_t>(i)] < key[static_cast<std::size_t>(j)];
          });
      }
    });
  }
  return order;
}

template struct GridSpec<2>;
template struct GridSpec<3>;
template GridSpec<2> make_grid_spec<2>(std::span<const Vec<2>>, Real);
template GridSpec<3> make_grid_spec<3>(std::span<const Vec<3>>, Real);
template std::vector<Index> cell_sort_order<2>(std::span<const Vec<2>>, Real,
                                               std::span<const std::int64_t>);
template std::vector<Index> cell_sort_order<3>(std::span<const Vec<3>>, Real,
                                               std::span<const std::int64_t>);
template void detail::bucket_by_cell<2>(std::span<const Vec<2>>, const GridSpec<2>&,
                                        std::vector<Index>&, std::vector<Index>&,
                                        std::vector<Index>&);
template void detail::bucket_by_cell<3>(std::span<const Vec<3>>, const GridSpec<3>&,
                                        std::vector<Index>&, std::vector<Index>&,
                                        std::vector<Index>&);

}  // namespace crater::neighbors
