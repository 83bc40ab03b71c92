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

  void barrier() const;
  /// Ends every rank of the run with `code` (MPI_Abort): for a failure one rank found alone,
  /// while the others would wait for it in a collective. Without MPI, std::exit(code).
  [[noreturn]] void abort(int code) const;
  Real max(Real x) const;
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

}  // namespace crater::parallel
