// The ranks of a run (issue 29, docs/distributed.md). A thin layer over MPI that the rest of
// crater calls instead of MPI itself, so that a build without MPI (CRATER_HAVE_MPI unset) and a
// process started without a launcher both see one rank and change nothing.
//
// Every collective here gives the same bits on every rank and for any rank count: the results
// are exact (minima, maxima, integer sums, sums of ReproducibleSum's exact levels) or
// concatenations in rank order. Only the thread that started MPI calls it (MPI_THREAD_FUNNELED:
// the OpenMP loops never communicate).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "core/types.hpp"
#include "parallel/reproducible_sum.hpp"

namespace crater::parallel {

class Comm {
 public:
  /// The ranks of this process's run: every rank of MPI_COMM_WORLD when a Session started MPI,
  /// else this process alone.
  static const Comm& world();

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  /// Whether MPI was started in this process (a launcher started it, even with one rank).
  bool mpi() const { return mpi_; }
  /// Wall time this process has spent in MPI's calls so far [s]: waiting for the other ranks
  /// and moving bytes (summary.json's run.time_by_rank_s.mpi). 0 without MPI.
  double seconds_in_mpi() const;

  void barrier() const;
  /// Ends every rank of the run with `code` (MPI_Abort): for a failure one rank found alone,
  /// while the others would wait for it in a collective. Without MPI, std::exit(code).
  [[noreturn]] void abort(int code) const;
  Real max(Real x) const;
  /// Element-wise maximum over the ranks, in place (exact).
  void max(std::span<Real> x) const;
  Real min(Real x) const;
  std::int64_t sum(std::int64_t x) const;

  /// A value and the id of the entity it belongs to (a stable step and the entity limiting it).
  struct ValueId {
    Real value = 0;
    std::int64_t id = -1;
  };
  /// The smallest value over the ranks; on equal values, the smallest id. Exact.
  ValueId min_with_id(ValueId x) const;

  /// Element-wise sum over the ranks of partial sums whose every partial sum is exact (the
  /// levels of a ReproducibleSum): any order of the additions gives the same bits.
  void sum_exact(std::span<Real> x) const;

  /// Every rank's bytes, concatenated in rank order, on every rank; `counts` (if given) gets
  /// each rank's byte count.
  std::vector<std::byte> all_gather(std::span<const std::byte> mine,
                                    std::vector<std::int64_t>* counts = nullptr) const;

  /// Every rank's bytes, concatenated in rank order, on rank 0 (`counts`: each rank's byte
  /// count there); the other ranks get nothing. For what rank 0 alone writes (frames,
  /// checkpoints).
  std::vector<std::byte> gather(std::span<const std::byte> mine,
                                std::vector<std::int64_t>* counts = nullptr) const;

  /// Sends send[r] to rank r (send has size() entries; send[rank()] stays here) and returns
  /// what each rank sent to this one, indexed by the source rank.
  std::vector<std::vector<std::byte>> all_to_all(
      const std::vector<std::vector<std::byte>>& send) const;

 private:
  friend class Session;
  int rank_ = 0;
  int size_ = 1;
  bool mpi_ = false;
};

/// Starts MPI for the lifetime of the object when a launcher started this process (mpirun,
/// srun: the environment names the process's rank) or CRATER_MPI=1 is set, and ends it in the
/// destructor. A plain start stays one rank without MPI: MPI_Init alone costs Open MPI 0.4 s on
/// this machine, which every `crater check` would pay. Make one, first thing in main().
class Session {
 public:
  Session(int& argc, char**& argv);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  /// Why MPI was not started ("" when it was): no launcher, or a build without MPI.
  static const char* why_single();
};

/// Every rank's values, concatenated in rank order, on every rank (trivially copyable T).
template <class T>
std::vector<T> all_gather(const Comm& comm, std::span<const T> mine) {
  static_assert(std::is_trivially_copyable_v<T>);
  const auto bytes = comm.all_gather(std::as_bytes(mine));
  std::vector<T> out(bytes.size() / sizeof(T));
  if (!out.empty()) std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
  return out;
}

/// Every rank's values, concatenated in rank order, on rank 0; nothing elsewhere.
template <class T>
std::vector<T> gather(const Comm& comm, std::span<const T> mine) {
  static_assert(std::is_trivially_copyable_v<T>);
  const auto bytes = comm.gather(std::as_bytes(mine));
  std::vector<T> out(bytes.size() / sizeof(T));
  if (!out.empty()) std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
  return out;
}

/// The sum over all ranks of every rank's `terms`, with the same bits whichever rank holds which
/// term and in whatever order (ReproducibleSum, made with the bounds of the whole set).
inline Real reproducible_sum(const Comm& comm, std::span<const Real> terms) {
  Real bound = 0;
  for (Real x : terms)
    if (std::isfinite(x)) bound = std::max(bound, std::abs(x));
  bound = comm.max(bound);
  const std::int64_t count = comm.sum(static_cast<std::int64_t>(terms.size()));
  ReproducibleSum s(bound, count);
  for (Real x : terms)
    s.add(x);
  auto partials = s.partials();
  comm.sum_exact(partials);
  s.set_partials(partials);
  return s.value();
}

/// The sums over every rank of K quantities, each term(i)[q] over the indices i in [0, n) of
/// this rank that `adds(i)` admits: the same bits whichever rank holds which index, on any
/// thread count, and without `comm` (one rank) as on any number of ranks. One ReproducibleSum
/// per quantity, made with the bounds of the whole set: three collectives (the maxima, the
/// count, the exact levels) whatever K. Every rank calls it, with or without indices.
/// `extra`, when given: one more term of each quantity from every rank (a part's running
/// total), counted and bounded as the others are.
template <std::size_t K, class Adds, class Term>
std::array<Real, K> reproducible_sums(const Comm* comm, Index n, Adds&& adds, Term&& term,
                                      const std::array<Real, K>* extra = nullptr) {
  std::array<Real, K> bound{};
  std::int64_t count = 0;
  if (extra) {
    count = 1;
    for (std::size_t q = 0; q < K; ++q)
      if (std::isfinite((*extra)[q])) bound[q] = std::abs((*extra)[q]);
  }
#pragma omp parallel if (n >= parallel_min())
  {
    std::array<Real, K> b{};
    std::int64_t c = 0;
#pragma omp for schedule(static) nowait
    for (Index i = 0; i < n; ++i) {
      if (!adds(i)) continue;
      ++c;
      const std::array<Real, K> x = term(i);
      for (std::size_t q = 0; q < K; ++q)
        if (std::isfinite(x[q])) b[q] = std::max(b[q], std::abs(x[q]));
    }
#pragma omp critical(crater_reproducible_sums)
    {
      count += c;
      for (std::size_t q = 0; q < K; ++q)
        bound[q] = std::max(bound[q], b[q]);
    }
  }
  if (comm) {
    comm->max(std::span<Real>(bound));
    count = comm->sum(count);
  }
  std::array<ReproducibleSum, K> empty;
  for (std::size_t q = 0; q < K; ++q)
    empty[q] = ReproducibleSum(bound[q], count);
  std::array<ReproducibleSum, K> total = empty;
#pragma omp parallel if (n >= parallel_min())
  {
    std::array<ReproducibleSum, K> local = empty;  // with the same bounds
#pragma omp for schedule(static) nowait
    for (Index i = 0; i < n; ++i) {
      if (!adds(i)) continue;
      const std::array<Real, K> x = term(i);
      for (std::size_t q = 0; q < K; ++q)
        local[q].add(x[q]);
    }
#pragma omp critical(crater_reproducible_sums)
    for (std::size_t q = 0; q < K; ++q)
      total[q].merge(local[q]);
  }
  if (extra)
    for (std::size_t q = 0; q < K; ++q)
      total[q].add((*extra)[q]);
  std::array<Real, K> out{};
  if (comm) {
    constexpr std::size_t kWords = ReproducibleSum::kLevels + 1;
    std::vector<Real> partials(K * kWords);
    for (std::size_t q = 0; q < K; ++q) {
      const auto p = total[q].partials();
      std::copy(p.begin(), p.end(), partials.begin() + static_cast<std::ptrdiff_t>(q * kWords));
    }
    comm->sum_exact(std::span<Real>(partials));
    for (std::size_t q = 0; q < K; ++q) {
      ReproducibleSum::Partials p{};
      std::copy_n(partials.begin() + static_cast<std::ptrdiff_t>(q * kWords), kWords, p.begin());
      total[q].set_partials(p);
    }
  }
  for (std::size_t q = 0; q < K; ++q)
    out[q] = total[q].value();
  return out;
}

}  // namespace crater::parallel
