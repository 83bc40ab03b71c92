// OpenMP helpers. Every reduction here gives the same bits for any thread count: the range is
// cut into fixed-size blocks independent of the number of threads, each block is summed in
// order, and the block sums are added in block order by one thread.
#pragma once

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <exception>
#include <utility>
#include <vector>

#include "core/types.hpp"

namespace crater::parallel {

/// Block size for deterministic reductions; fixed so that results never depend on threads.
/// Small enough that a few thousand entities make blocks for both threads in even shares.
inline constexpr Index kReduceBlock = 512;

/// Loops shorter than this run on the calling thread. A parallel region costs a fork and a
/// barrier; when another process holds a core (CI running tests side by side, a second job),
/// each barrier waits for a descheduled thread, and a small DEM bed ran 75x slower on 2 threads
/// than on 1. Results do not change: every loop here is thread-count independent. The
/// environment variable CRATER_PARALLEL_MIN overrides it (the determinism tests set 0, so that
/// their small cases do run in parallel).
inline Index parallel_min() {
  static const Index v = [] {
    const char* e = std::getenv("CRATER_PARALLEL_MIN");
    return e ? static_cast<Index>(std::strtoll(e, nullptr, 10)) : Index{2048};
  }();
  return v;
}

inline int max_threads() {
  return omp_get_max_threads();
}
inline void set_threads(int n) {
  if (n > 0) omp_set_num_threads(n);
  // A region inside a region runs on its one thread (alongside() relies on it): the default of
  // libgomp, made explicit against OMP_NESTED / OMP_MAX_ACTIVE_LEVELS in the environment.
  omp_set_max_active_levels(1);
}

/// What one index of a loop costs, against an update of an array entry or two (`light`). A
/// `heavy` index (an element's constitutive update, a particle's sum over its neighbours, a
/// search over candidate faces) takes about a microsecond, so a loop of a few hundred of them
/// already repays its fork and join: it runs in parallel from parallel_min() / 16 indices.
enum class Cost : Index { light = 1, heavy = 16 };

/// Whether a loop of n indices of `cost` each runs in parallel.
inline bool forks(Index n, Cost cost = Cost::light) {
  return n * static_cast<Index>(cost) >= parallel_min();
}

/// for i in [0, n): f(i), in parallel. f must only write to entity i's own data.
template <class F>
void for_each(Index n, F&& f, Cost cost = Cost::light) {
#pragma omp parallel for schedule(static) if (forks(n, cost))
  for (Index i = 0; i < n; ++i)
    f(i);
}

/// f(first, last) for the blocks [first, last) of `block` consecutive indices covering [0, n),
/// in parallel when n (the indices, not the blocks) reaches parallel_min(). f must only write
/// to its block's entities' own data. The blocks are dealt out as threads come free (their work
/// differs: a grain in a dense bed has many contacts, one in flight none), which does not
/// change what any block computes.
template <class F>
void for_each_block(Index n, Index block, F&& f, Cost cost = Cost::light) {
  const Index blocks = (n + block - 1) / block;
#pragma omp parallel for schedule(dynamic, 4) if (forks(n, cost))
  for (Index b = 0; b < blocks; ++b)
    f(b * block, std::min(n, (b + 1) * block));
}

/// main() on the calling thread while the team's other threads run block(b) for the b in
/// [0, blocks), dealt out `chunk` at a time as threads come free; the calling thread takes its
/// share of what remains once main() returns. What main() itself forks runs on the calling
/// thread alone (a region inside a region has one thread), so main() must not wait for the
/// blocks, nor a block for main(), and neither may write what the other reads. Every block runs
/// once, on some thread: what each computes does not depend on which, nor on the thread count.
/// An exception from main() or a block is rethrown once all have returned (main()'s first).
template <class Main, class Block>
void alongside(Index blocks, Index chunk, Main&& main, Block&& block) {
  std::exception_ptr main_error, block_error;
  auto run_main = [&] {
    try {
      main();
    } catch (...) {
      main_error = std::current_exception();
    }
  };
  auto run_block = [&](Index b) {
    try {
      block(b);
    } catch (...) {
#pragma omp critical(crater_alongside)
      if (!block_error) block_error = std::current_exception();
    }
  };
  if (blocks <= 0 || max_threads() == 1 || omp_in_parallel()) {
    run_main();
    for (Index b = 0; b < blocks; ++b)
      run_block(b);
  } else {
    std::atomic<Index> next{0};
#pragma omp parallel
    {
      if (omp_get_thread_num() == 0) run_main();
      for (;;) {
        const Index first = next.fetch_add(chunk, std::memory_order_relaxed);
        if (first >= blocks) break;
        for (Index b = first; b < std::min(blocks, first + chunk); ++b)
          run_block(b);
      }
    }
  }
  if (main_error) std::rethrow_exception(main_error);
  if (block_error) std::rethrow_exception(block_error);
}

/// Sum of f(i) over the i in [0, n) with keep(i), in deterministic_sum's fixed association
/// order (bit-identical for any thread count). Where f(i) would be T{} (all +0) for the i left
/// out, the result is deterministic_sum's bit for bit: a sum that starts at +0 never becomes -0,
/// and adding +0 to it changes nothing. T must support T{} + T and +=.
template <class T, class Keep, class F>
T deterministic_sum_if(Index n, Keep&& keep, F&& f) {
  const Index blocks = (n + kReduceBlock - 1) / kReduceBlock;
  if (blocks <= 1) {
    T s{};
    for (Index i = 0; i < n; ++i)
      if (keep(i)) s += f(i);
    return s;
  }
  std::vector<T> partial(static_cast<std::size_t>(blocks), T{});
#pragma omp parallel for schedule(static) if (n >= parallel_min())
  for (Index b = 0; b < blocks; ++b) {
    T s{};
    const Index end = std::min(n, (b + 1) * kReduceBlock);
    for (Index i = b * kReduceBlock; i < end; ++i)
      if (keep(i)) s += f(i);
    partial[static_cast<std::size_t>(b)] = s;
  }
  T s{};
  for (const T& p : partial)
    s += p;
  return s;
}

/// Sum of f(i) over [0, n) with a fixed association order (bit-identical for any thread count).
/// T must support T{} + T and +=.
template <class T, class F>
T deterministic_sum(Index n, F&& f) {
  return deterministic_sum_if<T>(
      n, [](Index) { return true; }, std::forward<F>(f));
}

/// The indices i in [0, n) with keep(i), ascending (a stream compaction: each fixed block counts
/// its kept indices, the counts become offsets, each block writes its own range).
template <class F>
std::vector<Index> select(Index n, F&& keep) {
  const Index blocks = (n + kReduceBlock - 1) / kReduceBlock;
  std::vector<Index> start(static_cast<std::size_t>(blocks) + 1, 0);
#pragma omp parallel for schedule(static) if (n >= parallel_min())
  for (Index b = 0; b < blocks; ++b) {
    Index kept = 0;
    const Index end = std::min(n, (b + 1) * kReduceBlock);
    for (Index i = b * kReduceBlock; i < end; ++i)
      kept += keep(i) ? 1 : 0;
    start[static_cast<std::size_t>(b) + 1] = kept;
  }
  for (std::size_t b = 0; b < static_cast<std::size_t>(blocks); ++b)
    start[b + 1] += start[b];
  std::vector<Index> out(static_cast<std::size_t>(start.back()));
#pragma omp parallel for schedule(static) if (n >= parallel_min())
  for (Index b = 0; b < blocks; ++b) {
    Index k = start[static_cast<std::size_t>(b)];
    const Index end = std::min(n, (b + 1) * kReduceBlock);
    for (Index i = b * kReduceBlock; i < end; ++i)
      if (keep(i)) out[static_cast<std::size_t>(k++)] = i;
  }
  return out;
}

/// Minimum of f(i) over [0, n) (min is associative and exact, so any order gives the same bits).
template <class F>
Real min_over(Index n, Real init, F&& f) {
  Real m = init;
#pragma omp parallel for schedule(static) reduction(min : m) if (n >= parallel_min())
  for (Index i = 0; i < n; ++i)
    m = std::min(m, f(i));
  return m;
}

/// Maximum of f(i) over [0, n) (exact in any order); `cost` as for for_each.
template <class F>
Real max_over(Index n, Real init, F&& f, Cost cost = Cost::light) {
  Real m = init;
#pragma omp parallel for schedule(static) reduction(max : m) if (forks(n, cost))
  for (Index i = 0; i < n; ++i)
    m = std::max(m, f(i));
  return m;
}

}  // namespace crater::parallel
