// Checks and boxes of point sets, shared by the neighbour searches (neighbor_list.cpp).
#pragma once

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "parallel/parallel.hpp"

namespace crater::neighbors::detail {

inline void check_radius(Real radius) {
  if (!(radius > 0) || !std::isfinite(radius)) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", radius);
    throw std::invalid_argument(std::string("neighbour search: radius must be positive and "
                                            "finite, got ") +
                                buf);
  }
}

// Cross lists name the set; self lists get the message of make_grid_spec.
template <int D>
void check_finite(std::span<const Vec<D>> x, const char* set) {
  const std::vector<Index> bad = parallel::select(static_cast<Index>(x.size()), [&](Index i) {
    return !x[static_cast<std::size_t>(i)].allFinite();
  });
  if (!bad.empty()) {
    throw std::invalid_argument("neighbour search: non-finite coordinate at point " +
                                std::to_string(bad.front()) + " of the " + set + " set");
  }
}

// The points of x inside `box` grown by `reach` on every side, ascending.
template <int D>
std::vector<Index> inside(std::span<const Vec<D>> x, const Eigen::AlignedBox<Real, D>& box,
                          Real reach) {
  const Vec<D> lo = box.min() - Vec<D>::Constant(reach);
  const Vec<D> hi = box.max() + Vec<D>::Constant(reach);
  return parallel::select(static_cast<Index>(x.size()), [&](Index i) {
    const Vec<D>& p = x[static_cast<std::size_t>(i)];
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
  });
}

// Bounding box of x (min and max are exact: any order of the blocks gives the same box).
template <int D>
Eigen::AlignedBox<Real, D> bounds(std::span<const Vec<D>> x) {
  const Index n = static_cast<Index>(x.size());
  const Index blocks = (n + parallel::kReduceBlock - 1) / parallel::kReduceBlock;
  std::vector<Eigen::AlignedBox<Real, D>> part(static_cast<std::size_t>(blocks));
#pragma omp parallel for schedule(static) if (n >= parallel::parallel_min())
  for (Index b = 0; b < blocks; ++b) {
    Eigen::AlignedBox<Real, D> box;
    const Index end = std::min(n, (b + 1) * parallel::kReduceBlock);
    for (Index i = b * parallel::kReduceBlock; i < end; ++i)
      box.extend(x[static_cast<std::size_t>(i)]);
    part[static_cast<std::size_t>(b)] = box;
  }
  Eigen::AlignedBox<Real, D> box;
  for (const auto& p : part)
    box.extend(p);
  return box;
}

template <int D>
Eigen::AlignedBox<Real, D> bounds(std::span<const Vec<D>> x, std::span<const Index> which) {
  Eigen::AlignedBox<Real, D> box;
  for (Index i : which)
    box.extend(x[static_cast<std::size_t>(i)]);
  return box;
}

}  // namespace crater::neighbors::detail
