// Cell-list build.
//
// The candidate set and the query set are bucketed on one grid (for a self list they are the
// same). Work goes cell by cell: the candidates of the 3^D cells around a query cell form
// 3^(D-1) contiguous ranges of the bucketed arrays (the three cells along the last axis are
// adjacent in row-major order), and every query point of the cell scans them with a vectorised
// loop. Lists must come out in ascending original index. When the original indices ascend
// across the ranges, as they do for points re-sorted by cell_sort_order, the ranges are scanned
// in place; otherwise the candidates are first copied and sorted by index, once per cell.
#include "neighbors/neighbor_list.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "neighbors/cell_grid.hpp"

namespace crater::neighbors {

namespace {

// Below this many points the OpenMP fork costs more than the loops.
constexpr Index kParallelMin = 4096;
// Cells per dynamic chunk: cells can hold very different numbers of points.
constexpr int kChunk = 64;

constexpr int ipow3(int d) {
  return d == 0 ? 1 : 3 * ipow3(d - 1);
}

// Copies of a dozen elements: an inline loop, not a library memmove call per copy.
template <class T>
inline void copy_short(const T* src, Index n, T* dst) {
#pragma omp simd
  for (Index k = 0; k < n; ++k) {
    dst[k] = src[k];
  }
}

// Points bucketed by cell: coordinates per axis in cell order and the original index of each
// sorted position.
template <int D>
struct Buckets {
  std::vector<Index> cell_start;
  std::vector<Index> order;  // sorted position -> original index
  std::vector<Index> cell;   // scratch of bucket_by_cell
  std::vector<Real> sorted;  // D blocks of n coordinates
  // descents[s]: number of s' in [1, s] with order[s'] < order[s' - 1]; a range [b, e) of
  // sorted positions has ascending original indices iff descents[e - 1] == descents[b].
  std::vector<Index> descents;
  Index n = 0;

  void fill(std::span<const Vec<D>> x, const GridSpec<D>& grid, bool par) {
    n = static_cast<Index>(x.size());
    detail::bucket_by_cell<D>(x, grid, cell_start, order, cell);
    sorted.resize(static_cast<std::size_t>(D * n));
    descents.resize(static_cast<std::size_t>(n));
    Real* out = sorted.data();
    const Index* ord = order.data();
    const Index nn = n;
#pragma omp parallel for schedule(static) if (par)
    for (Index s = 0; s < nn; ++s) {
      const Vec<D>& p = x[static_cast<std::size_t>(ord[s])];
      for (int a = 0; a < D; ++a) {
        out[a * nn + s] = p[a];
      }
    }
    Index* desc = descents.data();
    if (nn > 0) desc[0] = 0;
    for (Index s = 1; s < nn; ++s)
      desc[s] = desc[s - 1] + (ord[s] < ord[s - 1]);
  }
};

// Per calling thread, reused across calls so that a rebuild every step does not allocate.
template <int D>
struct Workspace {
  GridSpec<D> grid;
  Buckets<D> cand;
  Buckets<D> query;  // cross lists only
};

template <int D>
Workspace<D>& workspace() {
  thread_local Workspace<D> ws;
  return ws;
}

// The candidates of one stencil: ranges [begin[r], end[r]) into D blocks of `stride`
// coordinates from c and into the original indices j. Unless noted, j ascends within each
// range and from one range to the next.
template <int D>
struct Candidates {
  static constexpr int kMaxRanges = ipow3(D - 1);
  const Real* c = nullptr;
  Index stride = 0;
  const Index* j = nullptr;
  std::array<Index, kMaxRanges> begin{};
  std::array<Index, kMaxRanges> end{};
  int ranges = 0;
  Index count = 0;
};

// Per-thread scratch: a sorted copy of one stencil's candidates and one output row.
template <int D>
struct Scratch {
  Index cap = 0;
  std::vector<Index> pos;  // sorted positions of the candidates
  std::vector<Index> j;    // their original indices, ascending
  std::vector<Real> c;     // D blocks of cap coordinates
  std::vector<Index> row;

  void reserve(Index m) {
    if (m <= cap) return;
    cap = std::max(m, 2 * cap);
    const auto u = static_cast<std::size_t>(cap);
    pos.resize(u);
    j.resize(u);
    c.resize(u * D);
    row.resize(u);
  }
};

void check_radius(Real radius) {
  if (!(radius > 0) || !std::isfinite(radius)) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", radius);
    throw std::invalid_argument(std::string("neighbour search: radius must be positive and "
                                            "finite, got ") +
                                buf);
  }
}

template <int D>
IVec<D> coords_of_linear(const GridSpec<D>& g, Index c) {
  IVec<D> a;
  for (int k = D - 1; k > 0; --k) {
    a[k] = c % g.dims[k];
    c /= g.dims[k];
  }
  a[0] = c;
  return a;
}

// The candidate ranges around cell coordinates c, in place in the buckets (j not necessarily
// ascending: see ascending()).
template <int D>
Candidates<D> stencil(const GridSpec<D>& g, const Buckets<D>& b, const IVec<D>& c) {
  Candidates<D> v;
  v.c = b.sorted.data();
  v.stride = b.n;
  v.j = b.order.data();
  const Index* cs = b.cell_start.data();
  const Index dl = g.dims[D - 1];
  const Index lo = std::max<Index>(c[D - 1] - 1, 0);
  const Index hi = std::min<Index>(c[D - 1] + 1, dl - 1);
  const auto add = [&](Index base) {
    const Index begin = cs[base + lo];
    const Index end = cs[base + hi + 1];
    if (begin == end) return;
    v.begin[static_cast<std::size_t>(v.ranges)] = begin;
    v.end[static_cast<std::size_t>(v.ranges)] = end;
    v.count += end - begin;
    ++v.ranges;
  };
  const Index a0_lo = std::max<Index>(c[0] - 1, 0);
  const Index a0_hi = std::min<Index>(c[0] + 1, g.dims[0] - 1);
  if constexpr (D == 2) {
    for (Index a0 = a0_lo; a0 <= a0_hi; ++a0)
      add(a0 * dl);
  } else {
    const Index a1_lo = std::max<Index>(c[1] - 1, 0);
    const Index a1_hi = std::min<Index>(c[1] + 1, g.dims[1] - 1);
    for (Index a0 = a0_lo; a0 <= a0_hi; ++a0) {
      for (Index a1 = a1_lo; a1 <= a1_hi; ++a1)
        add((a0 * g.dims[1] + a1) * dl);
    }
  }
  return v;
}

// Whether the original indices ascend through all ranges of v (taken in place from b).
template <int D>
bool ascending(const Buckets<D>& b, const Candidates<D>& v) {
  const Index* desc = b.descents.data();
  for (int r = 0; r < v.ranges; ++r) {
    const auto ur = static_cast<std::size_t>(r);
    if (desc[v.end[ur] - 1] != desc[v.begin[ur]]) return false;
    if (r > 0 && b.order[static_cast<std::size_t>(v.begin[ur])] <
                     b.order[static_cast<std::size_t>(v.end[ur - 1] - 1)]) {
      return false;
    }
  }
  return true;
}

// Copies the candidates of v into s in ascending original index; returns a one-range view.
// Insertion sort for the usual few dozen candidates (ascending runs, often nearly in order).
template <int D>
Candidates<D> sorted_copy(const Buckets<D>& b, const Candidates<D>& v, Scratch<D>& s) {
  const Index m = v.count;
  s.reserve(m);
  Index* pos = s.pos.data();
  Index* j = s.j.data();
  const Index* order = b.order.data();
  Index t = 0;
  for (int r = 0; r < v.ranges; ++r) {
    const auto ur = static_cast<std::size_t>(r);
    for (Index k = v.begin[ur]; k < v.end[ur]; ++k) {
      pos[t] = k;
      j[t] = order[k];
      ++t;
    }
  }
  if (m > 256) {
    std::sort(pos, pos + m, [order](Index u, Index w) { return order[u] < order[w]; });
    for (Index q = 0; q < m; ++q)
      j[q] = order[pos[q]];
  } else {
    for (Index q = 1; q < m; ++q) {
      const Index kj = j[q];
      const Index kp = pos[q];
      Index w = q;
      for (; w > 0 && j[w - 1] > kj; --w) {
        j[w] = j[w - 1];
        pos[w] = pos[w - 1];
      }
      j[w] = kj;
      pos[w] = kp;
    }
  }
  for (int a = 0; a < D; ++a) {
    const Real* src = b.sorted.data() + a * b.n;
    Real* dst = s.c.data() + a * s.cap;
    for (Index q = 0; q < m; ++q)
      dst[q] = src[pos[q]];
  }
  Candidates<D> out;
  out.c = s.c.data();
  out.stride = s.cap;
  out.j = s.j.data();
  out.begin[0] = 0;
  out.end[0] = m;
  out.ranges = 1;
  out.count = m;
  return out;
}

// Which candidates a list keeps besides the distance test.
enum class Keep {
  All,         // cross lists
  AllButSelf,  // Pairs::Full
  Greater,     // Pairs::Half
};

// Squared distance from q to candidate b. Both passes evaluate this one expression (no FMA
// contraction in ISO C++ mode), so they agree on every candidate.
template <int D>
inline Real dist2(const Real* c, Index stride, Index b, const Real* q) {
  Real d = c[b] - q[0];
  Real d2 = d * d;
  for (int a = 1; a < D; ++a) {
    d = c[a * stride + b] - q[a];
    d2 += d * d;
  }
  return d2;
}

// First candidate of range r to consider: with Keep::Greater, the first with j > i.
template <int D, Keep keep>
inline Index range_begin(const Candidates<D>& v, std::size_t r, Index i) {
  if constexpr (keep == Keep::Greater) {
    return std::upper_bound(v.j + v.begin[r], v.j + v.end[r], i) - v.j;
  } else {
    return v.begin[r];
  }
}

// Row length of query point q (original index i). Keep::Greater needs ascending j.
template <int D, Keep keep>
inline Index count_query(const Candidates<D>& v, const std::array<Real, D>& q, Index i, Real r2) {
  // Counted in floating point: GCC vectorises a double compare into a double sum, not into an
  // integer one. Exact below 2^53.
  Real cnt = 0;
  for (int r = 0; r < v.ranges; ++r) {
    const auto ur = static_cast<std::size_t>(r);
    const Index e = v.end[ur];
#pragma omp simd reduction(+ : cnt)
    for (Index b = range_begin<D, keep>(v, ur, i); b < e; ++b) {
      cnt += dist2<D>(v.c, v.stride, b, q.data()) <= r2 ? Real(1) : Real(0);
    }
  }
  // The point itself is at distance 0 and was counted once.
  if constexpr (keep == Keep::AllButSelf) cnt -= 1;
  return static_cast<Index>(cnt);
}

// Writes the kept original indices of query point q, ascending, to row and returns their
// number. The distance tests of up to 64 candidates are packed into a bit mask (vectorised) and
// the kept candidates are read off its set bits.
template <int D, Keep keep>
inline Index fill_query(const Candidates<D>& v, const std::array<Real, D>& q, Index i, Real r2,
                        Index* row) {
  Index t = 0;
  for (int r = 0; r < v.ranges; ++r) {
    const auto ur = static_cast<std::size_t>(r);
    const Index e = v.end[ur];
    for (Index base = range_begin<D, keep>(v, ur, i); base < e; base += 64) {
      const Index len = std::min<Index>(64, e - base);
      std::uint64_t mask = 0;
#pragma omp simd reduction(| : mask)
      for (Index b = 0; b < len; ++b) {
        const std::uint64_t kept = dist2<D>(v.c, v.stride, base + b, q.data()) <= r2 ? 1 : 0;
        mask |= kept << b;
      }
      for (; mask != 0; mask &= mask - 1) {
        const Index jj = v.j[base + std::countr_zero(mask)];
        row[t] = jj;
        if constexpr (keep == Keep::AllButSelf) {
          t += jj != i;  // i itself is at distance 0
        } else {
          ++t;
        }
      }
    }
  }
  return t;
}

// The per-cell kernels are also compiled for AVX2 where GCC supports function multi-versioning
// (the clone is chosen once at load time). Results do not depend on the clone: each candidate
// goes through the same IEEE operations (no FMA), and counts are exact integers.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define CRATER_NEIGHBORS_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CRATER_NEIGHBORS_CLONES
#endif

template <int D>
inline std::array<Real, D> query_point(const Buckets<D>& qb, Index t) {
  std::array<Real, D> q;
  for (int a = 0; a < D; ++a) {
    q[static_cast<std::size_t>(a)] = qb.sorted[static_cast<std::size_t>(a * qb.n + t)];
  }
  return q;
}

// Row lengths of the query points [t0, t1) of one cell into count[i].
template <int D, Keep keep>
CRATER_NEIGHBORS_CLONES void count_cell(const Candidates<D>& v, const Buckets<D>& qb, Index t0,
                                        Index t1, Real r2, Index* count) {
  for (Index t = t0; t < t1; ++t) {
    const Index i = qb.order[static_cast<std::size_t>(t)];
    count[i] = count_query<D, keep>(v, query_point(qb, t), i, r2);
  }
}

// Rows of the query points [t0, t1) of one cell, copied to their slots in out. Returns the
// number of rows whose length disagrees with the count pass: 0 unless the distance test was
// miscompiled, and then no row is written past its slot.
template <int D, Keep keep>
CRATER_NEIGHBORS_CLONES Index fill_cell(const Candidates<D>& v, const Buckets<D>& qb, Index t0,
                                        Index t1, Real r2, Index* row, NeighborList& out) {
  Index bad = 0;
  const Index* off = out.offsets.data();
  Index* idx = out.indices.data();
  for (Index t = t0; t < t1; ++t) {
    const Index i = qb.order[static_cast<std::size_t>(t)];
    const Index m = fill_query<D, keep>(v, query_point(qb, t), i, r2, row);
    const Index len = off[i + 1] - off[i];
    copy_short(row, std::min(m, len), idx + off[i]);
    bad += m != len;
  }
  return bad;
}

// Lists for the query points qb (bucketed on grid) against the candidates cb; for a self list
// both are the same object. out.offsets must have (number of queries + 1) entries.
template <int D, Keep keep>
void build(const GridSpec<D>& grid, const Buckets<D>& cb, const Buckets<D>& qb, Real radius,
           bool par, NeighborList& out) {
  const Index ncell = grid.cell_count();
  const Index* qcs = qb.cell_start.data();
  const Real r2 = radius * radius;

  // Pass 1: row lengths into offsets[i + 1]. Only Half lists need ascending indices here.
  Index* count = out.offsets.data() + 1;
#pragma omp parallel if (par)
  {
    thread_local Scratch<D> s;
#pragma omp for schedule(dynamic, kChunk)
    for (Index c = 0; c < ncell; ++c) {
      if (qcs[c] == qcs[c + 1]) continue;
      Candidates<D> v = stencil<D>(grid, cb, coords_of_linear(grid, c));
      if constexpr (keep == Keep::Greater) {
        if (!ascending(cb, v)) v = sorted_copy(cb, v, s);
      }
      count_cell<D, keep>(v, qb, qcs[c], qcs[c + 1], r2, count);
    }
  }

  Index* o = out.offsets.data();
  const Index nq = out.size();
  o[0] = 0;
  for (Index i = 0; i < nq; ++i)
    o[i + 1] += o[i];
  out.indices.resize(static_cast<std::size_t>(o[nq]));

  // Pass 2: fill.
  Index bad_rows = 0;
#pragma omp parallel if (par) reduction(+ : bad_rows)
  {
    thread_local Scratch<D> s;
#pragma omp for schedule(dynamic, kChunk)
    for (Index c = 0; c < ncell; ++c) {
      if (qcs[c] == qcs[c + 1]) continue;
      Candidates<D> v = stencil<D>(grid, cb, coords_of_linear(grid, c));
      if (!ascending(cb, v)) v = sorted_copy(cb, v, s);
      s.reserve(v.count);
      bad_rows += fill_cell<D, keep>(v, qb, qcs[c], qcs[c + 1], r2, s.row.data(), out);
    }
  }
  if (bad_rows != 0) {
    throw std::logic_error("neighbour search: count and fill passes disagree on " +
                           std::to_string(bad_rows) + " rows");
  }
}

}  // namespace

template <int D>
void build_neighbor_list(std::span<const Vec<D>> x, Real radius, Pairs mode, NeighborList& out) {
  check_radius(radius);
  out.offsets.resize(x.size() + 1);
  out.offsets[0] = 0;
  if (x.empty()) {
    out.indices.clear();
    return;
  }
  const bool par = static_cast<Index>(x.size()) >= kParallelMin;
  Workspace<D>& ws = workspace<D>();
  ws.grid = make_grid_spec<D>(x, radius);  // validates coordinates
  ws.cand.fill(x, ws.grid, par);
  if (mode == Pairs::Full) {
    build<D, Keep::AllButSelf>(ws.grid, ws.cand, ws.cand, radius, par, out);
  } else {
    build<D, Keep::Greater>(ws.grid, ws.cand, ws.cand, radius, par, out);
  }
}

template <int D>
void build_cross_list(std::span<const Vec<D>> a, std::span<const Vec<D>> b, Real radius,
                      NeighborList& out) {
  check_radius(radius);
  const Index na = static_cast<Index>(a.size());
  for (Index i = 0; i < na; ++i) {
    if (!a[static_cast<std::size_t>(i)].allFinite()) {
      throw std::invalid_argument("neighbour search: non-finite coordinate at point " +
                                  std::to_string(i) + " of the query set");
    }
  }
  out.offsets.assign(static_cast<std::size_t>(na + 1), 0);
  if (na == 0 || b.empty()) {
    out.indices.clear();
    return;
  }
  const bool par = std::max<Index>(na, static_cast<Index>(b.size())) >= kParallelMin;
  Workspace<D>& ws = workspace<D>();
  ws.grid = make_grid_spec<D>(b, radius);  // validates b
  ws.cand.fill(b, ws.grid, par);
  // Query points outside b's box clamp to a boundary cell, whose stencil still covers every
  // candidate within the radius (see cell_grid.hpp).
  ws.query.fill(a, ws.grid, par);
  build<D, Keep::All>(ws.grid, ws.cand, ws.query, radius, par, out);
}

template void build_neighbor_list<2>(std::span<const Vec<2>>, Real, Pairs, NeighborList&);
template void build_neighbor_list<3>(std::span<const Vec<3>>, Real, Pairs, NeighborList&);
template void build_cross_list<2>(std::span<const Vec<2>>, std::span<const Vec<2>>, Real,
                                  NeighborList&);
template void build_cross_list<3>(std::span<const Vec<3>>, std::span<const Vec<3>>, Real,
                                  NeighborList&);

}  // namespace crater::neighbors
