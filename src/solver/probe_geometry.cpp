// The geometry behind the 3D probes; see probe_geometry.hpp.
#include "solver/probe_geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "core/index.hpp"

namespace crater::solver {

std::vector<Ring> ring_profile(const std::vector<Real>& r_m, const std::vector<Real>& surface0_m,
                               const std::vector<Real>& surface_m, Real width_m) {
  struct Sum {
    Real r = 0, s0 = 0, s = 0;
    Index n = 0;
  };
  std::vector<Sum> sums;
  for (std::size_t k = 0; k < r_m.size(); ++k) {
    if (!std::isfinite(r_m[k]) || !std::isfinite(surface0_m[k]) || !std::isfinite(surface_m[k]))
      continue;
    const auto j = static_cast<std::size_t>(std::floor(std::max(Real(0), r_m[k]) / width_m));
    if (j >= sums.size()) sums.resize(j + 1);
    sums[j].r += r_m[k];
    sums[j].s0 += surface0_m[k];
    sums[j].s += surface_m[k];
    ++sums[j].n;
  }
  std::vector<Ring> rings;
  for (const Sum& s : sums) {
    if (s.n == 0) continue;
    const auto n = static_cast<Real>(s.n);
    rings.push_back({s.r / n, s.s0 / n, s.s / n});
  }
  return rings;
}

CraterSize crater_of_profile(const std::vector<Ring>& rings, Real threshold_m) {
  CraterSize c;
  if (rings.empty()) return c;
  std::size_t deepest = 0;
  for (std::size_t j = 1; j < rings.size(); ++j)
    if (rings[j].drop_m() > rings[deepest].drop_m()) deepest = j;
  if (!(rings[deepest].drop_m() > threshold_m)) return c;
  c.depth_m = rings[deepest].drop_m();
  c.radius_m = rings.back().r_m;
  c.reaches_end = true;
  for (std::size_t j = deepest + 1; j < rings.size(); ++j) {
    if (rings[j].drop_m() > threshold_m) continue;
    // Ring j - 1 dropped by more than the threshold, ring j not: the crossing lies between.
    const Ring& in = rings[j - 1];
    const Ring& out = rings[j];
    const Real f = (in.drop_m() - threshold_m) / (in.drop_m() - out.drop_m());
    c.radius_m = in.r_m + f * (out.r_m - in.r_m);
    c.reaches_end = false;
    break;
  }
  return c;
}

namespace {

/// Area of the convex hull of points in the plane (Andrew's monotone chain, then the shoelace
/// formula).
Real hull_area(std::vector<std::array<Real, 2>> p) {
  std::sort(p.begin(), p.end());
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return 0;
  auto cross = [](const std::array<Real, 2>& o, const std::array<Real, 2>& a,
                  const std::array<Real, 2>& b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  };
  std::vector<std::array<Real, 2>> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {  // lower hull
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0)
      --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {  // upper hull
    while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0)
      --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  Real a = 0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    const auto& u = h[i];
    const auto& v = h[(i + 1) % h.size()];
    a += u[0] * v[1] - v[0] * u[1];
  }
  return std::abs(a) / 2;
}

}  // namespace

template <int D>
Real perforated_footprint(const PlateCells<D>& plate) {
  constexpr int H = D - 1;  // horizontal axes
  const auto& x = plate.reference;
  const std::size_t nn = x.size(), ne = plate.offsets.size();
  if (ne == 0 || nn == 0) return 0;
  // Nodes on one vertical line have equal horizontal coordinates up to round-off (reference =
  // position - displacement): per axis, coordinates closer than 1e-9 of the plate's extent
  // are one value (a chain of such steps too), and a node's key is those values' ranks.
  Real extent = 0;
  for (int a = 0; a < H; ++a) {
    const auto [lo, hi] = std::minmax_element(
        x.begin(), x.end(), [a](const Vec<D>& p, const Vec<D>& q) { return p[a] < q[a]; });
    extent = std::max(extent, (*hi)[a] - (*lo)[a]);
  }
  const Real tol = 1e-9 * std::max(extent, Real(1e-300));
  std::vector<std::array<Index, H>> key(nn);
  std::vector<std::size_t> order(nn);
  for (int a = 0; a < H; ++a) {
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(),
              [&](std::size_t i, std::size_t j) { return x[i][a] < x[j][a]; });
    Index rank = -1;
    Real previous = 0;
    for (const std::size_t i : order) {
      if (rank < 0 || x[i][a] - previous > tol) ++rank;
      previous = x[i][a];
      key[i][at(a)] = rank;
    }
  }
  // Each element's footprint: the distinct keys of its nodes; equal footprints are a column.
  std::vector<std::vector<std::array<Index, H>>> foot(ne);
  std::int64_t begin = 0;
  for (std::size_t e = 0; e < ne; ++e) {
    for (std::int64_t k = begin; k < plate.offsets[e]; ++k)
      foot[e].push_back(key[at(plate.connectivity[at(k)])]);
    std::sort(foot[e].begin(), foot[e].end());
    foot[e].erase(std::unique(foot[e].begin(), foot[e].end()), foot[e].end());
    begin = plate.offsets[e];
  }
  std::vector<std::size_t> elements(ne);
  std::iota(elements.begin(), elements.end(), std::size_t{0});
  std::stable_sort(elements.begin(), elements.end(),
                   [&](std::size_t a, std::size_t b) { return foot[a] < foot[b]; });
  Real area = 0;
  for (std::size_t g = 0; g < ne;) {
    std::size_t end = g;
    bool all_eroded = true;
    while (end < ne && foot[elements[end]] == foot[elements[g]]) {
      all_eroded = all_eroded && plate.eroded[elements[end]] != 0;
      ++end;
    }
    if (all_eroded) {
      const std::size_t e = elements[g];
      const std::int64_t first = e == 0 ? 0 : plate.offsets[e - 1];
      if constexpr (D == 2) {
        Real lo = x[at(plate.connectivity[at(first)])][0], hi = lo;
        for (std::int64_t k = first; k < plate.offsets[e]; ++k) {
          lo = std::min(lo, x[at(plate.connectivity[at(k)])][0]);
          hi = std::max(hi, x[at(plate.connectivity[at(k)])][0]);
        }
        area += hi - lo;
      } else {
        std::vector<std::array<Real, 2>> p;
        for (std::int64_t k = first; k < plate.offsets[e]; ++k) {
          const Vec<D>& n = x[at(plate.connectivity[at(k)])];
          p.push_back({n[0], n[1]});
        }
        area += hull_area(std::move(p));
      }
    }
    g = end;
  }
  return area;
}

template Real perforated_footprint<2>(const PlateCells<2>&);
template Real perforated_footprint<3>(const PlateCells<3>&);

}  // namespace crater::solver
