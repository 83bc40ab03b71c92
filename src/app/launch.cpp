// `crater run … --ranks N`: see launch.hpp.
#include "app/launch.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "core/error.hpp"

namespace crater::app {
namespace {

// The launcher: $CRATER_MPIEXEC, else the one the build found beside the MPI it links.
std::string launcher() {
  if (const char* env = std::getenv("CRATER_MPIEXEC"); env && *env) return env;
  return CRATER_MPIEXEC;
}

int cores() {
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

}  // namespace

int threads_per_rank(int ranks) {
  return std::max(1, cores() / std::max(1, ranks));
}

void run_under_launcher(int ranks, int threads, int argc, char** argv) {
  const std::string mpiexec = launcher();
  if (mpiexec.empty())
    throw InputError({}, "--ranks",
                     "a crater built with MPI (this one was built without: install Debian's "
                     "libopenmpi-dev and rebuild), or --ranks 1");
  if (::access(mpiexec.c_str(), X_OK) != 0)
    throw InputError({}, "--ranks",
                     fmt::format("an MPI launcher to start the ranks: {} cannot be run ({}); set "
                                 "CRATER_MPIEXEC to mpiexec's path, or start crater under mpirun",
                                 mpiexec, std::strerror(errno)));
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) throw InputError({}, "--ranks", "this program's path (/proc/self/exe): " + ec.message());
  const int n_cores = cores();
  // Open MPI's settings by environment (other launchers ignore them), a user's own kept.
  if (ranks > n_cores) {
    ::setenv("OMPI_MCA_rmaps_base_oversubscribe", "1", 0);
    spdlog::warn(
        "{} ranks on {} cores: the ranks share cores (oversubscribed), which is slower "
        "than {} ranks",
        ranks, n_cores, n_cores);
  } else if (ranks * threads > n_cores) {
    spdlog::warn("{} ranks x {} threads on {} cores: threads share cores", ranks, threads, n_cores);
  }
  if (threads > 1) ::setenv("OMPI_MCA_hwloc_base_binding_policy", "none", 0);
  std::vector<std::string> args{mpiexec, "-n", std::to_string(ranks), self.string()};
  for (int k = 1; k < argc; ++k)
    args.emplace_back(argv[k]);
  std::vector<char*> c_args;
  for (std::string& a : args)
    c_args.push_back(a.data());
  c_args.push_back(nullptr);
  spdlog::info("on {} ranks: {} -n {} crater …", ranks, mpiexec, ranks);
  std::fflush(stdout);
  std::fflush(stderr);
  ::execv(mpiexec.c_str(), c_args.data());
  throw InputError({}, "--ranks",
                   fmt::format("an MPI launcher to start the ranks: {} failed to start ({})",
                               mpiexec, std::strerror(errno)));
}

}  // namespace crater::app
