// The explicit time loop of the paper's Algorithm 1, shared by every method:
//   1. dt = safety x min over parts of their stable step (or the user's fixed step, checked)
//   2. advance every part from t to t + dt (half kick with the current forces, drift)
//   3. compute forces of the new state: per part, then couplings between parts
//   4. check every part for non-finite or non-physical values (exit 3 on failure)
//   5. finish the step (second half kick); energy bookkeeping, history, output frames
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "io/output/run_directory.hpp"
#include "io/scenario/config.hpp"
#include "solver/part_names.hpp"

namespace crater::solver {

struct RunOptions {
  std::filesystem::path out_dir = "out";
  int threads = 0;                // 0: all cores
  bool force = false;             // overwrite a run directory that already holds a run
  bool quiet = false;             // no progress output (tests)
  std::filesystem::path restart;  // a checkpoint to continue from (empty: start at t = 0)
  io::RunCommand command;         // how the run was started (crater-command.toml, summary.json)
};

/// Stable step of one part, as `crater check` prints it.
struct PartReport {
  std::string name;
  std::string method;
  Index count = 0;
  Real mass_kg = 0;
  StableStep stable;
  std::vector<Diagnostic> bed;  // a DEM part's solid_fraction and bulk_density_kg_m3
  bool unsettled = false;       // its packing is not in the cache yet: the run settles it first
};

/// What happened; also written to summary.json.
struct RunResult {
  Index steps = 0;
  Index first_step = 0;  // where this process started: non-zero on a resumed run
  Real time_s = 0;
  double wall_s = 0;
  double loop_s = 0;      // the time loop alone: wall_s without the setup and the final output
  double loop_mpi_s = 0;  // of loop_s, in MPI's calls (parallel::Comm::seconds_in_mpi)
  int threads = 1;
  int ranks = 1;  // MPI ranks the parts were spread over (Part::distribute)
  // Multi-rate stepping: the steps each part took (scenario order); empty otherwise.
  std::vector<std::pair<std::string, std::int64_t>> steps_by_part;
  // loop_s split by where it went: each part's stages (scenario order), the contacts between
  // parts, the probes, the outputs (history, frames, progress, checkpoints), the rest.
  // Of each part's stages and of the contacts, the time in MPI's calls (parts_mpi_s in the order
  // of parts_s): on ranks, the waits for the others show where the load parts.
  struct TimeByPart {
    std::vector<std::pair<std::string, double>> parts_s;
    double contacts_s = 0, probes_s = 0, output_s = 0, other_s = 0;
    std::vector<double> parts_mpi_s;
    double contacts_mpi_s = 0;
  } time_by_part;
};

/// Builds the parts, checks the time step, and reports counts, masses and stable steps.
/// Throws InputError for a fixed step above the stable limit.
std::vector<PartReport> check_scenario(const io::Config& config);

/// Runs a scenario to its end time, writing outputs into options.out_dir.
/// Throws InputError (exit 2) or NumericalError (exit 3, after writing the failure state).
RunResult run_scenario(const io::Config& config, const RunOptions& options);

}  // namespace crater::solver
