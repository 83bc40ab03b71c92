#include "parallel/comm.hpp"

#include <chrono>
#include <climits>
#include <cstdlib>
#include <string>

#ifdef CRATER_HAVE_MPI
#include <mpi.h>
#endif

namespace crater::parallel {

namespace {

Comm& world_mutable() {
  static Comm w;
  return w;
}

#ifdef CRATER_HAVE_MPI
bool g_started = false;

// The environment a launcher gives its processes: Open MPI's mpirun, PMIx (Open MPI, Slurm's
// srun --mpi=pmix), PMI (MPICH's hydra, srun --mpi=pmi2).
bool launched() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(v)) return true;
  const char* forced = std::getenv("CRATER_MPI");
  return forced && std::string(forced) == "1";
}

int to_int_count(std::size_t n) {
  if (n > static_cast<std::size_t>(INT_MAX))
    throw std::runtime_error("a message of " + std::to_string(n) +
                             " bytes exceeds MPI's int counts (2 GiB per rank pair)");
  return static_cast<int>(n);
}

// Wall time this process spent in MPI's calls (Comm::seconds_in_mpi): waiting for the other
// ranks and moving the bytes. Only the thread that started MPI calls it (MPI_THREAD_FUNNELED).
double g_in_mpi_s = 0;
struct InMpi {
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  ~InMpi() {
    g_in_mpi_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
};

// Element-wise `op` over the ranks of every entry of x, in place.
void reduce_in_place(std::span<Real> x, MPI_Op op) {
  const InMpi timed;
  MPI_Allreduce(MPI_IN_PLACE, x.data(), to_int_count(x.size()), MPI_DOUBLE, op, MPI_COMM_WORLD);
}
#endif

}  // namespace

const Comm& Comm::world() {
  return world_mutable();
}

double Comm::seconds_in_mpi() const {
#ifdef CRATER_HAVE_MPI
  return g_in_mpi_s;
#else
  return 0;
#endif
}

Session::Session([[maybe_unused]] int& argc, [[maybe_unused]] char**& argv) {
#ifdef CRATER_HAVE_MPI
  if (!launched()) return;
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  g_started = true;
  Comm& w = world_mutable();
  MPI_Comm_rank(MPI_COMM_WORLD, &w.rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &w.size_);
  w.mpi_ = true;
#endif
}

Session::~Session() {
#ifdef CRATER_HAVE_MPI
  if (g_started) {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
    g_started = false;
  }
#endif
}

const char* Session::why_single() {
#ifdef CRATER_HAVE_MPI
  return g_started ? "" : "not started by a launcher (mpirun, srun)";
#else
  return "this crater was built without MPI (install libopenmpi-dev and rebuild)";
#endif
}

void Comm::abort(int code) const {
#ifdef CRATER_HAVE_MPI
  if (mpi_) MPI_Abort(MPI_COMM_WORLD, code);
#endif
  std::exit(code);
}

void Comm::barrier() const {
#ifdef CRATER_HAVE_MPI
  if (mpi_) {
    const InMpi timed;
    MPI_Barrier(MPI_COMM_WORLD);
  }
#endif
}

Real Comm::max(Real x) const {
#ifdef CRATER_HAVE_MPI
  if (mpi_) {
    const InMpi timed;
    MPI_Allreduce(MPI_IN_PLACE, &x, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  }
#endif
  return x;
}

void Comm::max([[maybe_unused]] std::span<Real> x) const {
#ifdef CRATER_HAVE_MPI
  if (mpi_) reduce_in_place(x, MPI_MAX);
#endif
}

Real Comm::min(Real x) const {
#ifdef CRATER_HAVE_MPI
  if (mpi_) {
    const InMpi timed;
    MPI_Allreduce(MPI_IN_PLACE, &x, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  }
#endif
  return x;
}

std::int64_t Comm::sum(std::int64_t x) const {
#ifdef CRATER_HAVE_MPI
  if (mpi_) {
    const InMpi timed;
    MPI_Allreduce(MPI_IN_PLACE, &x, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  }
#endif
  return x;
}

Comm::ValueId Comm::min_with_id(ValueId x) const {
  if (size_ == 1) return x;
  // MPI_MINLOC carries an int, too narrow for ids: gather the pairs and pick in rank order.
  const auto all = parallel::all_gather(*this, std::span<const ValueId>(&x, 1));
  ValueId best = all.front();
  for (const ValueId& v : all)
    if (v.value < best.value || (v.value == best.value && v.id < best.id)) best = v;
  return best;
}

void Comm::sum_exact([[maybe_unused]] std::span<Real> x) const {
#ifdef CRATER_HAVE_MPI
  if (mpi_) reduce_in_place(x, MPI_SUM);
#endif
}

namespace {

// Every rank's bytes concatenated in rank order, on every rank (`everyone`) or on rank 0 alone
// (the others get nothing); `counts`: each rank's byte count where the bytes arrive.
std::vector<std::byte> collect(std::span<const std::byte> mine, std::vector<std::int64_t>* counts,
                               [[maybe_unused]] int rank, int size, bool mpi,
                               [[maybe_unused]] bool everyone) {
  if (!mpi || size == 1) {
    if (counts) *counts = {static_cast<std::int64_t>(mine.size())};
    return {mine.begin(), mine.end()};
  }
#ifdef CRATER_HAVE_MPI
  const InMpi timed;
  int n = to_int_count(mine.size());
  std::vector<int> count(static_cast<std::size_t>(size)), offset(static_cast<std::size_t>(size));
  if (everyone)
    MPI_Allgather(&n, 1, MPI_INT, count.data(), 1, MPI_INT, MPI_COMM_WORLD);
  else
    MPI_Gather(&n, 1, MPI_INT, count.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  const bool receives = everyone || rank == 0;
  std::size_t total = 0;
  if (receives)
    for (std::size_t r = 0; r < count.size(); ++r) {
      offset[r] = to_int_count(total);
      total += static_cast<std::size_t>(count[r]);
    }
  std::vector<std::byte> out(total);
  if (everyone)
    MPI_Allgatherv(mine.data(), n, MPI_BYTE, out.data(), count.data(), offset.data(), MPI_BYTE,
                   MPI_COMM_WORLD);
  else
    MPI_Gatherv(mine.data(), n, MPI_BYTE, out.data(), count.data(), offset.data(), MPI_BYTE, 0,
                MPI_COMM_WORLD);
  if (counts) {
    if (receives)
      counts->assign(count.begin(), count.end());
    else
      counts->clear();
  }
  return out;
#else
  return {};
#endif
}

}  // namespace

std::vector<std::byte> Comm::all_gather(std::span<const std::byte> mine,
                                        std::vector<std::int64_t>* counts) const {
  return collect(mine, counts, rank_, size_, mpi_, true);
}

std::vector<std::byte> Comm::gather(std::span<const std::byte> mine,
                                    std::vector<std::int64_t>* counts) const {
  return collect(mine, counts, rank_, size_, mpi_, false);
}

std::vector<std::vector<std::byte>> Comm::all_to_all(
    const std::vector<std::vector<std::byte>>& send) const {
  if (static_cast<int>(send.size()) != size_)
    throw std::logic_error("Comm::all_to_all: one buffer per rank expected");
  if (!mpi_ || size_ == 1) return send;
#ifdef CRATER_HAVE_MPI
  const InMpi timed;
  const auto p = static_cast<std::size_t>(size_);
  std::vector<int> send_count(p), send_offset(p), recv_count(p), recv_offset(p);
  std::vector<std::byte> send_all;
  for (std::size_t r = 0; r < p; ++r) {
    send_count[r] = to_int_count(send[r].size());
    send_offset[r] = to_int_count(send_all.size());
    send_all.insert(send_all.end(), send[r].begin(), send[r].end());
  }
  MPI_Alltoall(send_count.data(), 1, MPI_INT, recv_count.data(), 1, MPI_INT, MPI_COMM_WORLD);
  std::size_t total = 0;
  for (std::size_t r = 0; r < p; ++r) {
    recv_offset[r] = to_int_count(total);
    total += static_cast<std::size_t>(recv_count[r]);
  }
  std::vector<std::byte> recv_all(total);
  MPI_Alltoallv(send_all.data(), send_count.data(), send_offset.data(), MPI_BYTE, recv_all.data(),
                recv_count.data(), recv_offset.data(), MPI_BYTE, MPI_COMM_WORLD);
  std::vector<std::vector<std::byte>> out(p);
  for (std::size_t r = 0; r < p; ++r) {
    const auto first = recv_all.begin() + recv_offset[r];
    out[r].assign(first, first + recv_count[r]);
  }
  return out;
#else
  return send;
#endif
}

}  // namespace crater::parallel
