// Cell-list build.
//
// The candidate set and the query set are bucketed on one grid (for a self list
// they are the same). Work goes cell by cell: the candidates of the 3^D cells
// around a query cell form 3^(D-1) contiguous ranges of the bucketed arrays
// (the three cells along the last axis are adjacent in row-major order), and
// every query point of the cell scans them with a vectorised loop. Lists must
// come out in ascending original index. When the original indices ascend across
// the ranges, as they do for points re-sorted by cell_sort_order, the ranges
// are scanned in place; otherwise the candidates are first copied and sorted by
// index, once per cell.
#include "neighbors/neighbor_list.hpp"

#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "neighbors/cell_grid.hpp"
#include "neighbors/point_sets.hpp"
#include "parallel/parallel.hpp"

namespace crater::neighbors {

using detail::bounds;
using detail::check_finite;
using detail::check_radius;
using detail::inside;

namespace {

// Cells per dynamic chunk: cells can hold very different numbers of points.
constexpr int kChunk = 64;

constexpr int ipow3(int d) {
  return d == 0 ? 1 : 3 * ipow3(d - 1);
}

// Copies of a dozen elements: an inline loop, not a library memmove call per
// copy.
template <class T>
inline void copy_short(const T* src, Index n, T* dst) {
#pragma omp simd
  for (Index k = 0; k < n; ++k) {
    dst[k] = src[k];
  }
}

// Points bucketed by cell: coordinates per axis in cell order and the original
// index of each sorted position.
template <int D>
struct Buckets {
  std::vector<Index> cell_start;
  std::vector<Index> order;  // sorted position -> original index
  std::vector<Index> cell;   // scratch of bucket_by_cell
  std::vector<Real> sorted;  // D blocks of n coordinates
  // descents[s]: number of s' in [1, s] with order[s'] < order[s' - 1]; a range
  // [b, e) of sorted positions has ascending original indices iff descents[e -
  // 1] == descents[b].
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
    if (nn > 0) {
      desc[0] = 0;
    }
    for (Index s = 1; s < nn; ++s) {
      desc[s] = desc[s - 1] + (ord[s] < ord[s - 1]);
    }
  }
};

// Per calling thread, reused across calls so that a rebuild every step does not
// allocate. Where the count pass left the masks of one query cell: thread -1
// when it kept none.
struct MaskRef {
  int thread = -1;
  Index offset = 0;
};

template <int D>
struct Workspace {
  GridSpec<D> grid;
  Buckets<D> cand;
  Buckets<D> query;  // cross lists only
  std::vector<MaskRef> masks;
};

template <int D>
Workspace<D>& workspace() {
  thread_local Workspace<D> ws;
  return ws;
}

// The candidates of one stencil: ranges [begin[r], end[r]) into D blocks of
// `stride` coordinates from c and into the original indices j. Unless noted, j
// ascends within each range and from one range to the next.
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

// Query points per block in the kernels below.
constexpr int kRowLanes = 4;

// Per-thread scratch: a sorted copy of one stencil's candidates and one output
// row per lane.
template <int D>
struct Scratch {
  Index cap = 0;
  std::vector<Index> pos;  // sorted positions of the candidates
  std::vector<Index> j;    // their original indices, ascending
  std::vector<Real> c;     // D blocks of cap coordinates
  std::vector<Index> row;
  // Distance masks kept by the count pass for the fill pass (see build).
  std::vector<std::uint64_t> masks;
  Index masks_used = 0;

  // Room for n more masks; returns the offset of the first.
  Index take_masks(Index n) {
    const Index at = masks_used;
    masks_used += n;
    if (static_cast<Index>(masks.size()) < masks_used) {
      masks.resize(static_cast<std::size_t>(std::max(masks_used, 2 * at)));
    }
    return at;
  }

  void reserve(Index m) {
    if (m <= cap) {
      return;
    }
    cap = std::max(m, 2 * cap);
    const auto u = static_cast<std::size_t>(cap);
    pos.resize(u);
    j.resize(u);
    c.resize(u * D);
    row.resize(u * kRowLanes);
  }
};

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

// The candidate ranges around cell coordinates c, in place in the buckets (j
// not necessarily ascending: see ascending()).
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
    if (begin == end) {
      return;
    }
    v.begin[static_cast<std::size_t>(v.ranges)] = begin;
    v.end[static_cast<std::size_t>(v.ranges)] = end;
    v.count += end - begin;
    ++v.ranges;
  };
  const Index a0_lo = std::max<Index>(c[0] - 1, 0);
  const Index a0_hi = std::min<Index>(c[0] + 1, g.dims[0] - 1);
  if constexpr (D == 2) {
    for (Index a0 = a0_lo; a0 <= a0_hi; ++a0) {
      add(a0 * dl);
    }
  } else {
    const Index a1_lo = std::max<Index>(c[1] - 1, 0);
    const Index a1_hi = std::min<Index>(c[1] + 1, g.dims[1] - 1);
    for (Index a0 = a0_lo; a0 <= a0_hi; ++a0) {
      for (Index a1 = a1_lo; a1 <= a1_hi; ++a1) {
        add((a0 * g.dims[1] + a1) * dl);
      }
    }
  }
  return v;
}

// Whether the original indices ascend through all ranges of v (taken in place
// from b).
template <int D>
bool ascending(const Buckets<D>& b, const Candidates<D>& v) {
  const Index* desc = b.descents.data();
  for (int r = 0; r < v.ranges; ++r) {
    const auto ur = static_cast<std::size_t>(r);
    if (desc[v.end[ur] - 1] != desc[v.begin[ur]]) {
      return false;
    }
    if (r > 0 && b.order[static_cast<std::size_t>(v.begin[ur])] <
                     b.order[static_cast<std::size_t>(v.end[ur - 1] - 1)]) {
      return false;
    }
  }
  return true;
}

// Copies the candidates of v into s in ascending original index; returns a
// one-range view. Insertion sort for the usual few dozen candidates (ascending
// runs, often nearly in order).
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
    for (Index q = 0; q < m; ++q) {
      j[q] = order[pos[q]];
    }
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
    for (Index q = 0; q < m; ++q) {
      dst[q] = src[pos[q]];
    }
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

// Query points are processed in blocks of kLanes (points of one cell), so that
// the loop over a candidate range is set up once per block rather than once per
// point; the compiler vectorises over candidates or lanes as it sees fit.
constexpr int kLanes = kRowLanes;

template <int D>
struct QueryBlock {
  std::array<std::array<Real, kLanes>, D> q;  // q[axis][lane]
  std::array<Index, kLanes> i;                // original indices
  int live;                                   // lanes in use; the others never match
};

// The helpers below are forced inline so that they are compiled for the
// instruction set of the kernel clone that calls them (see
// CRATER_NEIGHBORS_CLONES).
template <int D>
[[gnu::always_inline]] inline QueryBlock<D> load_block(const Buckets<D>& qb, Index t, Index t1) {
  QueryBlock<D> blk;
  blk.live = static_cast<int>(std::min<Index>(kLanes, t1 - t));
  for (int l = 0; l < kLanes; ++l) {
    const auto ul = static_cast<std::size_t>(l);
    for (int a = 0; a < D; ++a) {
      // An infinite coordinate puts an unused lane at infinite distance from
      // every candidate.
      blk.q[static_cast<std::size_t>(a)][ul] =
          l < blk.live ? qb.sorted[static_cast<std::size_t>(a * qb.n + t + l)]
                       : std::numeric_limits<Real>::infinity();
    }
    blk.i[ul] = l < blk.live ? qb.order[static_cast<std::size_t>(t + l)] : -1;
  }
  return blk;
}

// kLanes values, one per query point of a block (GCC/Clang vector extension):
// the distance test of one candidate against a whole block is a handful of
// vector instructions, whatever the instruction set the clone below is compiled
// for.
using Lanes = Real __attribute__((vector_size(kLanes * sizeof(Real))));
using LaneBits = std::uint64_t __attribute__((vector_size(kLanes * sizeof(std::uint64_t))));

// Bit b of mask[l] is set when candidate base + b is within the radius of lane
// l (len <= 64). Both passes call this one function, so they agree on every
// pair; each pair goes through the same IEEE operations whatever the vector
// width (no FMA contraction in ISO C++ mode).
template <int D>
[[gnu::always_inline]] inline void block_masks(const Candidates<D>& v, Index base, Index len,
                                               const QueryBlock<D>& blk, Real r2,
                                               std::array<std::uint64_t, kLanes>& mask) {
  const Real* x = v.c + base;
  const Real* y = v.c + v.stride + base;
  const Real* z = v.c + (D == 3 ? 2 * v.stride : 0) + base;
  Lanes qx;
  Lanes qy;
  Lanes qz;
  Lanes rr;
  LaneBits bit;
  for (int l = 0; l < kLanes; ++l) {
    const auto ul = static_cast<std::size_t>(l);
    qx[l] = blk.q[0][ul];
    qy[l] = blk.q[1][ul];
    qz[l] = blk.q[D == 3 ? 2 : 0][ul];
    rr[l] = r2;
    bit[l] = 1;
  }
  LaneBits m{};
  for (Index b = 0; b < len; ++b, bit += bit) {
    const Lanes dx = x[b] - qx;
    const Lanes dy = y[b] - qy;
    Lanes d2 = dx * dx + dy * dy;
    if constexpr (D == 3) {
      const Lanes dz = z[b] - qz;
      d2 += dz * dz;
    }
    m |= reinterpret_cast<LaneBits>(d2 <= rr) & bit;
  }
  for (int l = 0; l < kLanes; ++l) {
    mask[static_cast<std::size_t>(l)] = m[l];
  }
}

// With Keep::Greater, clears the bits of candidates with j <= i (a prefix, j
// ascending).
template <int D, Keep keep>
[[gnu::always_inline]] inline void keep_greater(const Candidates<D>& v, Index base, Index len,
                                                const QueryBlock<D>& blk,
                                                std::array<std::uint64_t, kLanes>& mask) {
  if constexpr (keep == Keep::Greater) {
    const Index* j = v.j + base;
    for (int l = 0; l < blk.live; ++l) {
      const auto ul = static_cast<std::size_t>(l);
      const Index first = std::upper_bound(j, j + len, blk.i[ul]) - j;
      mask[ul] = first >= 64 ? 0 : mask[ul] & (~std::uint64_t{0} << first);
    }
  }
}

// Number of chunks for_each_chunk visits.
template <int D>
inline Index chunk_count(const Candidates<D>& v) {
  Index n = 0;
  for (int r = 0; r < v.ranges; ++r) {
    const auto ur = static_cast<std::size_t>(r);
    n += (v.end[ur] - v.begin[ur] + 63) / 64;
  }
  return n;
}

// Calls f(base, mask) for each chunk of at most 64 candidates of each range of
// v.
template <int D, Keep keep, class F>
[[gnu::always_inline]] inline void for_each_chunk(const Candidates<D>& v, const QueryBlock<D>& blk,
                                                  Real r2, F&& f) {
  std::array<std::uint64_t, kLanes> mask;
  for (int r = 0; r < v.ranges; ++r) {
    const auto ur = static_cast<std::size_t>(r);
    for (Index base = v.begin[ur]; base < v.end[ur]; base += 64) {
      const Index len = std::min<Index>(64, v.end[ur] - base);
      block_masks<D>(v, base, len, blk, r2, mask);
      keep_greater<D, keep>(v, base, len, blk, mask);
      f(base, mask);
    }
  }
}

// The per-cell kernels are also compiled for AVX2 where GCC supports function
// multi-versioning (the clone is chosen once at load time). Results do not
// depend on the clone.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define CRATER_NEIGHBORS_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CRATER_NEIGHBORS_CLONES
#endif

// Row lengths of the query points [t0, t1) of one cell into count[i]; if store
// is not null, the masks go there too, kLanes per chunk, in visiting order.
// Keep::Greater needs ascending j; the other modes do not look at j.
template <int D, Keep keep>
CRATER_NEIGHBORS_CLONES void count_cell(const Candidates<D>& v, const Buckets<D>& qb, Index t0,
                                        Index t1, Real r2, Index* count, std::uint64_t* store) {
  for (Index t = t0; t < t1; t += kLanes) {
    const QueryBlock<D> blk = load_block(qb, t, t1);
    std::array<Index, kLanes> n{};
    for_each_chunk<D, keep>(v, blk, r2, [&](Index, const std::array<std::uint64_t, kLanes>& m) {
      for (int l = 0; l < kLanes; ++l) {
        n[static_cast<std::size_t>(l)] += std::popcount(m[static_cast<std::size_t>(l)]);
      }
      if (store != nullptr) {
        std::copy(m.begin(), m.end(), store);
        store += kLanes;
      }
    });
    for (int l = 0; l < blk.live; ++l) {
      const auto ul = static_cast<std::size_t>(l);
      // In a self list the point itself is at distance 0 and was counted once.
      count[blk.i[ul]] = n[ul] - (keep == Keep::AllButSelf ? 1 : 0);
    }
  }
}

// Sorts a row of n indices, ascending: insertion sort for the usual few dozen.
[[gnu::always_inline]] inline void sort_row(Index* row, Index n) {
  if (n > 64) {
    std::sort(row, row + n);
    return;
  }
  for (Index q = 1; q < n; ++q) {
    const Index j = row[q];
    Index w = q;
    for (; w > 0 && row[w - 1] > j; --w)
      row[w] = row[w - 1];
    row[w] = j;
  }
}

// Rows of the query points [t0, t1) of one cell, written to their slots in out;
// `rows` has room for kLanes rows of v.count entries. The masks come from
// `cached` (left by count_cell for the same v) or, if it is null, are computed
// again. `sort_rows`: v's indices do not ascend, so each row is sorted before it
// is written. Returns the number of rows whose length disagrees with the count
// pass: 0 unless the distance test was miscompiled, and then no row is written
// past its slot.
template <int D, Keep keep>
CRATER_NEIGHBORS_CLONES Index fill_cell(const Candidates<D>& v, const Buckets<D>& qb, Index t0,
                                        Index t1, Real r2, const std::uint64_t* cached,
                                        bool sort_rows, Index* rows, NeighborList& out) {
  const Index* off = out.offsets.data();
  Index* idx = out.indices.data();
  Index bad = 0;
  for (Index t = t0; t < t1; t += kLanes) {
    const QueryBlock<D> blk = load_block(qb, t, t1);
    std::array<Index, kLanes> n{};
    const auto append = [&](Index base, const std::array<std::uint64_t, kLanes>& m) {
      const Index* j = v.j + base;
      for (int l = 0; l < blk.live; ++l) {
        const auto ul = static_cast<std::size_t>(l);
        Index* row = rows + l * v.count;
        const Index self = blk.i[ul];
        Index k = n[ul];
        for (std::uint64_t mm = m[ul]; mm != 0; mm &= mm - 1) {
          const Index jj = j[std::countr_zero(mm)];
          row[k] = jj;
          if constexpr (keep == Keep::AllButSelf) {
            k += jj != self;  // the point itself is at distance 0
          } else {
            ++k;
          }
        }
        n[ul] = k;
      }
    };
    if (cached != nullptr) {
      std::array<std::uint64_t, kLanes> m;
      for (int r = 0; r < v.ranges; ++r) {
        const auto ur = static_cast<std::size_t>(r);
        for (Index base = v.begin[ur]; base < v.end[ur]; base += 64) {
          std::copy(cached, cached + kLanes, m.begin());
          cached += kLanes;
          append(base, m);
        }
      }
    } else {
      for_each_chunk<D, keep>(v, blk, r2, append);
    }
    for (int l = 0; l < blk.live; ++l) {
      const auto ul = static_cast<std::size_t>(l);
      const Index i = blk.i[ul];
      const Index len = off[i + 1] - off[i];
      if (sort_rows) sort_row(rows + l * v.count, n[ul]);
      copy_short(rows + l * v.count, std::min(n[ul], len), idx + off[i]);
      bad += n[ul] != len;
    }
  }
  return bad;
}

// Lists for the query points qb (bucketed on grid) against the candidates cb;
// for a self list both are the same object. out.offsets must have (number of
// queries + 1) entries.
//
// For cells whose candidates are scanned in place (ascending indices: the usual
// case once a part is re-sorted), the count pass keeps its distance masks in
// per-thread scratch and the fill pass only reads them off, so each pair is
// tested once. Other cells are tested again on a sorted copy.
template <int D, Keep keep>
void build(const GridSpec<D>& grid, const Buckets<D>& cb, const Buckets<D>& qb, Real radius,
           bool par, std::vector<MaskRef>& refs, NeighborList& out) {
  const Index ncell = grid.cell_count();
  const Index* qcs = qb.cell_start.data();
  const Real r2 = radius * radius;
  refs.resize(static_cast<std::size_t>(ncell));
  MaskRef* ref = refs.data();
  std::vector<const std::uint64_t*> masks_of_thread(
      static_cast<std::size_t>(par ? omp_get_max_threads() : 1));

  // Pass 1: row lengths into offsets[i + 1].
  Index* count = out.offsets.data() + 1;
#pragma omp parallel if (par)
  {
    thread_local Scratch<D> s;
    const int thread = omp_get_thread_num();
    s.masks_used = 0;
#pragma omp for schedule(dynamic, kChunk)
    for (Index c = 0; c < ncell; ++c) {
      ref[c] = MaskRef{};
      const Index t0 = qcs[c];
      const Index t1 = qcs[c + 1];
      if (t0 == t1) {
        continue;
      }
      Candidates<D> v = stencil<D>(grid, cb, coords_of_linear(grid, c));
      std::uint64_t* store = nullptr;
      // Only Keep::Greater needs its candidates ascending: the other modes take them as they
      // lie and sort each row (fill_cell), which costs less than sorting the stencil's
      // candidates of every cell (a cross list's second set is seldom in the grid's order).
      if (keep != Keep::Greater || ascending(cb, v)) {
        const Index blocks = (t1 - t0 + kLanes - 1) / kLanes;
        ref[c] = MaskRef{thread, s.take_masks(blocks * chunk_count(v) * kLanes)};
        store = s.masks.data() + ref[c].offset;
      } else if constexpr (keep == Keep::Greater) {
        v = sorted_copy(cb, v, s);
      }
      count_cell<D, keep>(v, qb, t0, t1, r2, count, store);
    }
    masks_of_thread[static_cast<std::size_t>(thread)] = s.masks.data();
  }

  Index* o = out.offsets.data();
  const Index nq = out.size();
  o[0] = 0;
  for (Index i = 0; i < nq; ++i) {
    o[i + 1] += o[i];
  }
  out.indices.resize(static_cast<std::size_t>(o[nq]));

  // Pass 2: fill.
  Index bad_rows = 0;
#pragma omp parallel if (par) reduction(+ : bad_rows)
  {
    thread_local Scratch<D> s;
#pragma omp for schedule(dynamic, kChunk)
    for (Index c = 0; c < ncell; ++c) {
      if (qcs[c] == qcs[c + 1]) {
        continue;
      }
      Candidates<D> v = stencil<D>(grid, cb, coords_of_linear(grid, c));
      const std::uint64_t* cached = nullptr;
      bool sort_rows = false;
      if (ref[c].thread >= 0) {
        cached = masks_of_thread[static_cast<std::size_t>(ref[c].thread)] + ref[c].offset;
        sort_rows = keep != Keep::Greater && !ascending(cb, v);
      } else {
        v = sorted_copy(cb, v, s);
      }
      s.reserve(v.count);
      bad_rows +=
          fill_cell<D, keep>(v, qb, qcs[c], qcs[c + 1], r2, cached, sort_rows, s.row.data(), out);
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
  // A query point's scan of its stencil's cells is heavy work (parallel.hpp).
  const bool par = parallel::forks(static_cast<Index>(x.size()), parallel::Cost::heavy);
  Workspace<D>& ws = workspace<D>();
  ws.grid = make_grid_spec<D>(x, radius);  // validates coordinates
  ws.cand.fill(x, ws.grid, par);
  if (mode == Pairs::Full) {
    build<D, Keep::AllButSelf>(ws.grid, ws.cand, ws.cand, radius, par, ws.masks, out);
  } else {
    build<D, Keep::Greater>(ws.grid, ws.cand, ws.cand, radius, par, ws.masks, out);
  }
}

namespace {

template <int D>
void build_cross_list_of(std::span<const Vec<D>> a, std::span<const Vec<D>> b, Real radius,
                         NeighborList& out) {
  const Index na = static_cast<Index>(a.size());
  out.offsets.assign(static_cast<std::size_t>(na + 1), 0);
  if (na == 0 || b.empty()) {
    out.indices.clear();
    return;
  }
  const bool par =
      parallel::forks(std::max<Index>(na, static_cast<Index>(b.size())), parallel::Cost::heavy);
  Workspace<D>& ws = workspace<D>();
  ws.grid = make_grid_spec<D>(b, radius);
  ws.cand.fill(b, ws.grid, par);
  // Query points outside b's box clamp to a boundary cell, whose stencil still
  // covers every candidate within the radius (see cell_grid.hpp).
  ws.query.fill(a, ws.grid, par);
  build<D, Keep::All>(ws.grid, ws.cand, ws.query, radius, par, ws.masks, out);
}

}  // namespace

// Only the points of either set near the other's bounding box can pair, so the search runs on
// those: the candidates within radius of the query box, then the queries within radius of
// those candidates' box (a charge or a plate against a whole soil bed: a few per cent of the
// grains). The subsets keep their order and the indices are mapped back, so the lists are the
// ones of the full sets. The boxes grow by 1.001 x radius, so that rounding in the comparison
// never drops a pair.
template <int D>
void build_cross_list(std::span<const Vec<D>> a, std::span<const Vec<D>> b, Real radius,
                      NeighborList& out) {
  check_radius(radius);
  check_finite<D>(a, "query");
  check_finite<D>(b, "candidate");
  const Index na = static_cast<Index>(a.size());
  if (na == 0 || b.empty()) {
    build_cross_list_of<D>(a, b, radius, out);
    return;
  }
  const Real reach = Real(1.001) * radius;
  const std::vector<Index> sub_b = inside<D>(b, bounds<D>(a), reach);
  if (sub_b.empty()) {
    out.offsets.assign(static_cast<std::size_t>(na + 1), 0);
    out.indices.clear();
    return;
  }
  const std::vector<Index> sub_a = inside<D>(a, bounds<D>(b, sub_b), reach);
  if (sub_a.size() == a.size() && sub_b.size() == b.size()) {
    build_cross_list_of<D>(a, b, radius, out);
    return;
  }
  std::vector<Vec<D>> xa(sub_a.size()), xb(sub_b.size());
  for (std::size_t k = 0; k < sub_a.size(); ++k)
    xa[k] = a[static_cast<std::size_t>(sub_a[k])];
  for (std::size_t k = 0; k < sub_b.size(); ++k)
    xb[k] = b[static_cast<std::size_t>(sub_b[k])];
  NeighborList sub;
  build_cross_list_of<D>(std::span<const Vec<D>>(xa), std::span<const Vec<D>>(xb), radius, sub);
  // Rows of the queries left out are empty; the others take their sub-row, mapped back.
  // A query's offset is that of the first kept query at or after it: fill each gap of left-out
  // queries (k - 1 and k are consecutive kept queries) with the offset where query k starts.
  out.offsets.resize(static_cast<std::size_t>(na + 1));
  const Index nk = static_cast<Index>(sub_a.size());
  parallel::for_each(nk + 1, [&](Index k) {
    const Index from = k == 0 ? 0 : sub_a[static_cast<std::size_t>(k) - 1] + 1;
    const Index to = k == nk ? na : sub_a[static_cast<std::size_t>(k)];
    const Index offset = sub.offsets[static_cast<std::size_t>(k)];
    for (Index i = from; i <= to; ++i)
      out.offsets[static_cast<std::size_t>(i)] = offset;
  });
  out.indices.resize(sub.indices.size());
  parallel::for_each(static_cast<Index>(sub.indices.size()), [&](Index k) {
    out.indices[static_cast<std::size_t>(k)] =
        sub_b[static_cast<std::size_t>(sub.indices[static_cast<std::size_t>(k)])];
  });
}

template <int D>
struct CrossIndex<D>::Impl {
  GridSpec<D> grid;
  Buckets<D> cand;
  Real radius = 0;
  mutable Buckets<D> query;
  mutable std::vector<MaskRef> masks;
};

template <int D>
CrossIndex<D>::CrossIndex() : impl_(std::make_unique<Impl>()) {}
template <int D>
CrossIndex<D>::~CrossIndex() = default;
template <int D>
CrossIndex<D>::CrossIndex(CrossIndex&&) noexcept = default;
template <int D>
CrossIndex<D>& CrossIndex<D>::operator=(CrossIndex&&) noexcept = default;

template <int D>
void CrossIndex<D>::build(std::span<const Vec<D>> b, Real radius) {
  check_radius(radius);
  check_finite<D>(b, "candidate");
  Impl& m = *impl_;
  built_ = false;
  m.radius = radius;
  if (!b.empty()) {
    m.grid = make_grid_spec<D>(b, radius);
    m.cand.fill(b, m.grid, parallel::forks(static_cast<Index>(b.size()), parallel::Cost::heavy));
  } else {
    m.cand.n = 0;
  }
  built_ = true;
}

template <int D>
void CrossIndex<D>::query(std::span<const Vec<D>> a, NeighborList& out) const {
  const Impl& m = *impl_;
  if (!built_) throw std::logic_error("neighbour search: query of an index not built");
  check_finite<D>(a, "query");
  const Index na = static_cast<Index>(a.size());
  out.offsets.assign(static_cast<std::size_t>(na + 1), 0);
  if (na == 0 || m.cand.n == 0) {
    out.indices.clear();
    return;
  }
  const bool par = parallel::forks(na, parallel::Cost::heavy);
  // Query points outside b's box clamp to a boundary cell, whose stencil still covers every
  // candidate within the radius (cell_grid.hpp).
  m.query.fill(a, m.grid, par);
  ::crater::neighbors::build<D, Keep::All>(m.grid, m.cand, m.query, m.radius, par, m.masks, out);
}

template class CrossIndex<2>;
template class CrossIndex<3>;

template void build_neighbor_list<2>(std::span<const Vec<2>>, Real, Pairs, NeighborList&);
template void build_neighbor_list<3>(std::span<const Vec<3>>, Real, Pairs, NeighborList&);
template void build_cross_list<2>(std::span<const Vec<2>>, std::span<const Vec<2>>, Real,
                                  NeighborList&);
template void build_cross_list<3>(std::span<const Vec<3>>, std::span<const Vec<3>>, Real,
                                  NeighborList&);
}  // namespace crater::neighbors
