// `crater run … --ranks N` (issue 29, docs/distributed.md "Running on several ranks"): the run on
// N MPI ranks of this machine without writing the launcher's command line. Started without a
// launcher, crater starts itself under mpiexec with the same arguments; each rank, started by
// the launcher, checks that the launcher gave it N ranks and runs as under `mpirun -np N`.
#pragma once

namespace crater::app {

/// The OpenMP threads each of `ranks` ranks on this machine takes when --threads is not given:
/// the machine's cores shared out, at least one.
int threads_per_rank(int ranks);

/// Replaces this process by the MPI launcher running this same command line on `ranks`
/// processes of this machine (execv: the launcher's exit code is the run's, and it passes
/// SIGINT and SIGTERM on to the ranks). `threads`: each rank's. With more ranks than cores
/// the launcher is let oversubscribe; with more than one thread a rank, ranks are not bound to
/// one core each (Open MPI binds them so by default). Throws InputError when there is no
/// launcher to start (a build without MPI, a launcher that is not there).
[[noreturn]] void run_under_launcher(int ranks, int threads, int argc, char** argv);

}  // namespace crater::app
