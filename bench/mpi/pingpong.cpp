// MPI latency and bandwidth between two ranks (issue 29's scaling model, docs/distributed.md):
// one-way time of a message (half a ping-pong's round trip) over sizes 8 B to 8 MB, and the time
// of an all-reduce of one double (a global step's minimum). Built only where Debian's
// libopenmpi-dev is installed (crater itself does not use MPI yet):
//   mpirun -np 2 build/release/bench/crater_mpi_pingpong
#include <mpi.h>

#include <cstdio>
#include <vector>

namespace {

double one_way_s(long bytes, int reps, int rank) {
  std::vector<char> buf(static_cast<std::size_t>(bytes));
  double dt = 0;
  for (int pass = 0; pass < 2; ++pass) {  // the first pass warms the transport up
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = MPI_Wtime();
    for (int r = 0; r < reps; ++r) {
      if (rank == 0) {
        MPI_Send(buf.data(), static_cast<int>(bytes), MPI_CHAR, 1, 0, MPI_COMM_WORLD);
        MPI_Recv(buf.data(), static_cast<int>(bytes), MPI_CHAR, 1, 0, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
      } else if (rank == 1) {
        MPI_Recv(buf.data(), static_cast<int>(bytes), MPI_CHAR, 0, 0, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
        MPI_Send(buf.data(), static_cast<int>(bytes), MPI_CHAR, 0, 0, MPI_COMM_WORLD);
      }
    }
    dt = (MPI_Wtime() - t0) / reps / 2;
  }
  return dt;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size < 2) {
    if (rank == 0) std::fprintf(stderr, "run it on 2 ranks: mpirun -np 2 %s\n", argv[0]);
    MPI_Finalize();
    return 2;
  }
  if (rank == 0) std::printf("bytes, one-way time [us], bandwidth [GB/s]\n");
  for (long bytes : {8L, 64L, 512L, 4096L, 32768L, 262144L, 1048576L, 8388608L}) {
    const int reps = bytes <= 4096 ? 20000 : bytes <= 262144 ? 2000 : 100;
    const double dt = one_way_s(bytes, reps, rank);
    if (rank == 0) std::printf("%9ld, %9.3f, %7.3f\n", bytes, dt * 1e6, bytes / dt / 1e9);
  }
  const double x = rank;
  double y = 0;
  const int reps = 20000;
  MPI_Barrier(MPI_COMM_WORLD);
  const double t0 = MPI_Wtime();
  for (int r = 0; r < reps; ++r)
    MPI_Allreduce(&x, &y, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  if (rank == 0)
    std::printf("all-reduce of one double on %d ranks: %.3f us\n", size,
                (MPI_Wtime() - t0) / reps * 1e6);
  MPI_Finalize();
  return 0;
}
