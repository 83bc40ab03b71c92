// crater command line: run, check, list, schema, report, sweep, verify.
//   crater run SCENARIO [--level L] [--out DIR] [--threads N] [--ranks N] [--set key=value]...
//              [--force]
//   crater run SCENARIO --resume DIR | --restart FILE   (continue from a checkpoint)
//   crater check SCENARIO [--level L] [--set key=value]...
//   crater list
//   crater schema [--markdown]
//   crater report DIR [--out DIR] [--times T1,T2,...]   (figures and report.md of a run)
//   crater sweep SCENARIO --vary KEY=v1,v2,... [...]    (a parameter study: docs/sweep.md)
//   crater verify [--quick] [--case NAME]...             (the verification cases: docs/verify.md)
// Exit codes: 0 done, 2 bad input (scenario, command line, run directory), 3 numerical
// failure (NaN, negative volume, lost particle, energy guard), 130 interrupted by SIGINT or
// SIGTERM (a checkpoint is written: continue with --resume), 1 other errors (e.g. a full or
// unwritable disk: summary.json says so when there is room, --resume continues from the
// newest complete checkpoint). An allocation that fails anyway (std::bad_alloc: check and run
// first refuse a scenario whose memory estimate exceeds output.memory_limit_fraction of the
// available memory) is reported as "out of memory" with exit 2 during setup (loading, building
// the parts, check) and 3 in the time loop.
#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <new>
#include <thread>

#include "app/launch.hpp"
#include "app/report.hpp"
#include "core/error.hpp"
#include "io/checkpoint/checkpoint.hpp"
#include "io/scenario/load.hpp"
#include "io/scenario/schema.hpp"
#include "io/scenario/validate.hpp"
#include "parallel/comm.hpp"
#include "solver/memory_estimate.hpp"
#include "solver/simulation.hpp"

namespace {

using namespace crater;

void print_input_error(const InputError& e) {
  if (const auto* many = dynamic_cast<const io::InputErrors*>(&e)) {
    for (const auto& one : many->all())
      std::fprintf(stderr, "error: %s\n", one.what());
    if (many->all().size() > 1)
      std::fprintf(stderr, "%zu errors; nothing was run.\n", many->all().size());
  } else {
    std::fprintf(stderr, "error: %s\n", e.what());
  }
}

int cmd_check(const std::string& scenario, const std::vector<std::string>& sets,
              const std::string& level) {
  const io::Config c = io::load_scenario(scenario, sets, level);
  fmt::print("scenario '{}' ({}){}, {}D, end time {:.6g} s, hash {}\n", c.name, c.file,
             c.level.empty() ? std::string() : ", level " + c.level, c.dimension, c.end_time_s,
             c.hash);
  if (!c.description.empty()) fmt::print("  {}\n", c.description);
  fmt::print("{}\n", solver::memory_line(solver::estimate_memory(c), solver::available_memory(),
                                         c.output.memory_limit_fraction));
  std::fflush(stdout);  // shown before a refusal on stderr
  const auto reports = solver::check_scenario(c);
  // Both step columns per row: a part's stability limit is scaled by the safety factor, the
  // contacts' accuracy bound is not (StableStep::absolute); the smallest allowed step rules.
  fmt::print("{:<16} {:<7} {:>11} {:>14} {:>13} {:>14}  {}\n", "part", "method", "count",
             "mass [kg]", "stable dt [s]", "allowed dt [s]", "limited by");
  const double safety = c.time.safety_factor;
  const solver::PartReport* limiting = nullptr;
  for (const auto& r : reports) {
    const bool contacts = r.method == std::string("contact");
    // The contacts' reason names the pair (and the node or particle, when one sets it).
    const std::string by = r.stable.reason.empty() ? std::string("-")
                           : contacts || r.stable.entity_id < 0
                               ? r.stable.reason
                               : fmt::format("entity {} ({})", r.stable.entity_id, r.stable.reason);
    fmt::print("{:<16} {:<7} {:>11} {:>14} {:>13.4e} {:>14.4e}  {}{}\n", r.name, r.method, r.count,
               contacts ? std::string("-") : fmt::format("{:.6g}", r.mass_kg), r.stable.dt_s,
               r.stable.allowed_s(safety), by,
               r.stable.absolute ? "; not scaled by the safety factor" : "");
    if (!limiting || r.stable.allowed_s(safety) < limiting->stable.allowed_s(safety)) limiting = &r;
  }
  if (c.dimension == 2) fmt::print("(2D: masses per metre of depth)\n");
  for (const auto& r : reports)
    if (r.bed.size() == 2)
      fmt::print(
          "{}: solid fraction {:.4f} of its region less the parts it is carved around, "
          "bulk density {:.1f} kg/m^3\n",
          r.name, r.bed[0].value, r.bed[1].value);
  for (const auto& r : reports)
    if (r.unsettled)
      fmt::print(
          "{}: packing not in the cache yet; the run settles it first (minutes at a fine "
          "resolution), then reuses it\n",
          r.name);
  if (limiting && limiting->stable.absolute)
    fmt::print("global step: {:.4e} s ({}: {}; an accuracy bound, not scaled by the safety factor)",
               limiting->stable.allowed_s(safety), limiting->name, limiting->stable.reason);
  else if (limiting)
    fmt::print("global step: {:.4e} s = {} x {:.4e} s (part '{}')",
               limiting->stable.allowed_s(safety), safety, limiting->stable.dt_s, limiting->name);
  if (c.time.fixed_dt_s) fmt::print("; fixed step {:.4e} s in use", *c.time.fixed_dt_s);
  fmt::print("\n");
  for (const auto& w : c.warnings)
    fmt::print("warning: {}\n", w);
  fmt::print("ok\n");
  return kExitOk;
}

int cmd_run(const std::string& scenario, const std::vector<std::string>& sets,
            const std::string& level, const solver::RunOptions& opt) {
  const io::Config c = io::load_scenario(scenario, sets, level);
  spdlog::info("scenario '{}', {}D, end time {:.6g} s -> {}", c.name, c.dimension, c.end_time_s,
               opt.out_dir.string());
  solver::RunOptions o = opt;
  o.command.scenario = scenario;
  std::error_code ec;
  const auto file = std::filesystem::absolute(c.file, ec);
  o.command.scenario_file = ec ? c.file : file.string();
  o.command.level = level;
  o.command.sets = sets;
  o.command.threads = opt.threads;
  const auto r = solver::run_scenario(c, o);
  spdlog::info("done: {} steps to t = {:.6g} s in {:.2f} s on {} thread(s){}", r.steps, r.time_s,
               r.wall_s, r.threads,
               r.first_step > 0 ? fmt::format(" ({} of them after resuming at step {})",
                                              r.steps - r.first_step, r.first_step)
                                : std::string());
  return kExitOk;
}

// The command line: the subcommands and their options, filled by CLI11.
struct CommandLine {
  CLI::App app{"crater: explosions in layered ground (SPH + DEM + FEM)", "crater"};
  std::string scenario;
  std::vector<std::string> sets;
  std::string level;
  solver::RunOptions opt;
  std::string out_dir = "out";
  int ranks = 0;  // --ranks (0: not given)
  std::string resume_dir, restart_file;
  bool markdown = false;
  crater::app::ReportOptions report_opt;
  CLI::App* run = nullptr;
  CLI::App* sweep = nullptr;
  CLI::App* verify = nullptr;

  CommandLine() {
    app.set_version_flag("--version", std::string("crater ") + CRATER_VERSION);
    app.require_subcommand(1);
    add_run();
    add_others();
  }

 private:
  void add_run() {
    run = app.add_subcommand("run", "Run a scenario (a file, or a bundled name)");
    run->add_option("scenario", scenario,
                    "Scenario file or bundled scenario name (with --resume: the run's own, "
                    "unless given)");
    run->add_option("--out,-o", out_dir, "Run directory (default: out)");
    run->add_option("--threads,-t", opt.threads, "OpenMP threads (default: all cores)")
        ->check(CLI::Range(1, 4096));
    run->add_option("--ranks", ranks,
                    "MPI ranks on this machine: crater starts itself under mpiexec, as `mpiexec "
                    "-n N crater run ...` (each rank then takes cores / N threads unless "
                    "--threads is given); under mpirun or srun it must match their count")
        ->check(CLI::Range(1, 65536));
    run->add_option("--level,-l", level,
                    "Resolution level of the scenario ([levels.<name>]: demo, coarse, medium, "
                    "fine for the bundled paper scenarios; several as a,b: applied in that "
                    "order, e.g. medium,wide); applied before --set");
    run->add_option("--set,-s", sets, "Override a scenario key: dotted.key=VALUE (TOML)");
    run->add_flag("--force,-f", opt.force, "Overwrite a run directory that already holds a run");
    run->add_flag("--quiet,-q", opt.quiet,
                  "No progress line and no info lines; warnings and errors are still shown");
    auto* resume_opt = run->add_option(
        "--resume", resume_dir,
        "Continue the run in DIR from its newest valid checkpoint (DIR/checkpoints/), with the "
        "scenario, --level, --set and --threads it was started with (DIR/crater-command.toml) "
        "unless given again; --set given now follow the run's own. A finished run ends on a "
        "checkpoint: extend it with --set scenario.end_time_s=LATER (only the end time, the "
        "step cap, the guards and the outputs but their interval may change)");
    run->add_option("--restart", restart_file,
                    "Continue from this checkpoint file, into --out (a new or emptied directory: "
                    "the earlier frames and history are carried over) or, without --out, into "
                    "the run directory that holds it")
        ->excludes(resume_opt);
  }

  void add_others() {
    auto* check = app.add_subcommand("check", "Validate a scenario; print counts, masses, steps");
    check->add_option("scenario", scenario, "Scenario file or bundled scenario name")->required();
    check->add_option("--level,-l", level,
                      "Resolution level ([levels.<name>] of the scenario; several as a,b)");
    check->add_option("--set,-s", sets, "Override a scenario key: dotted.key=VALUE (TOML)");

    app.add_subcommand("list", "List the bundled scenarios");
    auto* schema = app.add_subcommand("schema", "Print the scenario file reference");
    schema->add_flag("--markdown", markdown, "Markdown (docs/scenario-format.md)");

    sweep = app.add_subcommand(
        "sweep",
        "Run a scenario over a grid or Latin hypercube of key values, in parallel processes, "
        "resumable; sweep.csv and design charts (crater sweep --help; docs/sweep.md)");
    // Everything after `sweep`, --help included, goes to the sweep script unparsed.
    sweep->prefix_command();
    sweep->allow_extras();
    sweep->set_help_flag();

    verify = app.add_subcommand(
        "verify",
        "Run the bundled verification cases (installed with the binary) and compare each with its "
        "reference: a table, verify.json, exit 1 on a failure (crater verify --help; "
        "docs/verify.md)");
    verify->prefix_command();
    verify->allow_extras();
    verify->set_help_flag();

    auto* report = app.add_subcommand(
        "report", "Figures (PNG) and report.md for a run directory (or a sweep's charts)");
    report->add_option("dir", report_opt.run_dir, "Run directory written by crater run")
        ->required();
    report->add_option("--out,-o", report_opt.out_dir, "Where to write (default: DIR/report)");
    report->add_option("--times", report_opt.times,
                       "Snapshot times [s], comma-separated: the nearest output frames (default: "
                       "up to 4 spread over the run, the last included)");
    report->add_option("--metrics", report_opt.metrics,
                       "A sweep's: the sweep.csv columns to chart, comma-separated (default: "
                       "every summary metric that varies, up to 12)");
  }
};

int cmd_list() {
  for (const auto& n : io::bundled_scenarios()) {
    std::string desc, levels;
    try {
      const io::Config c = io::load_scenario(n, {});
      desc = c.description;
      for (const auto& l : c.levels)
        levels += (levels.empty() ? "" : ", ") + l.name;
    } catch (const InputError& e) {
      desc = std::string("(invalid: ") + e.what() + ")";
    }
    fmt::print("{:<24} {}\n", n, desc);
    if (!levels.empty()) fmt::print("{:<24} levels: {}\n", "", levels);
  }
  return kExitOk;
}

// `run`: where it writes and what it continues from (--resume, --restart).
void resolve_run(CommandLine& cl, int argc, char** argv) {
  solver::RunOptions& opt = cl.opt;
  opt.out_dir = cl.out_dir;
  for (int k = 0; k < argc; ++k)
    opt.command.argv.emplace_back(argv[k]);
  if (!cl.resume_dir.empty()) {
    opt.out_dir = cl.resume_dir;
    opt.restart = io::newest_checkpoint(cl.resume_dir);
    // The run's own scenario and overrides, unless the command line names them again.
    if (cl.scenario.empty() || std::filesystem::exists(cl.resume_dir + "/" + io::kCommandName)) {
      const io::RunCommand was = io::read_run_command(cl.resume_dir);
      if (cl.scenario.empty())
        cl.scenario = std::filesystem::exists(was.scenario_file) ? was.scenario_file : was.scenario;
      // The run's own overrides first, then the ones given now: the keys a continued run may
      // change (the end time, the outputs; load.cpp's kRunControlKeys), e.g. to extend it.
      if (cl.level.empty()) cl.level = was.level;
      std::vector<std::string> sets = was.sets;
      sets.insert(sets.end(), cl.sets.begin(), cl.sets.end());
      cl.sets = std::move(sets);
      if (cl.run->count("--threads") == 0) opt.threads = was.threads;
    }
  } else if (!cl.restart_file.empty()) {
    opt.restart = cl.restart_file;
    if (cl.run->count("--out") == 0)
      opt.out_dir = std::filesystem::path(cl.restart_file).parent_path().parent_path();
  }
}

// `run --ranks N`: started by a launcher, its rank count must be N; started alone with N > 1,
// crater starts itself under the launcher (and does not return). Each rank takes cores / N
// threads unless --threads (or the resumed run's) says otherwise.
void start_ranks(CommandLine& cl, int argc, char** argv) {
  const auto& world = crater::parallel::Comm::world();
  if (world.mpi() && world.size() != cl.ranks)
    throw InputError({}, "--ranks",
                     fmt::format("the launcher's rank count, {} (--ranks {} was given under a "
                                 "launcher that started {}): leave --ranks out under mpirun or "
                                 "srun, or give it their count",
                                 world.size(), cl.ranks, world.size()));
  if (cl.run->count("--threads") == 0 && cl.resume_dir.empty())
    cl.opt.threads = crater::app::threads_per_rank(cl.ranks);
  if (!world.mpi() && cl.ranks > 1)
    crater::app::run_under_launcher(cl.ranks, cl.opt.threads, argc, argv);
}

// The exit code of what a command threw, with its message on stderr.
// Says what failed; `quiet_shared`: not the errors every rank finds alike (another rank says
// them), and then `*kept_quiet` tells whether it said nothing.
int report_failure_here(const std::exception_ptr& failure, const std::string& out_dir_for_resume,
                        bool quiet_shared, bool* kept_quiet = nullptr) {
  if (kept_quiet) *kept_quiet = false;
  try {
    std::rethrow_exception(failure);
  } catch (const InputError& e) {
    if (quiet_shared && kept_quiet) *kept_quiet = true;
    if (!quiet_shared) print_input_error(e);
    return kExitInput;
  } catch (const Interrupted& e) {
    std::fprintf(stderr,
                 "crater: %s; checkpoint and outputs written\ncontinue with: crater run "
                 "--resume %s\n",
                 e.what(), out_dir_for_resume.c_str());
    return kExitInterrupted;
  } catch (const NumericalError& e) {
    if (quiet_shared) {
      if (kept_quiet) *kept_quiet = true;
      return kExitNumerical;
    }
    std::fprintf(stderr,
                 "error: %s\n(the state at failure is in the run directory, "
                 "*_failure.vtu)\n",
                 e.what());
    return kExitNumerical;
  } catch (const std::bad_alloc&) {
    const bool in_loop = solver::current_activity() == solver::Activity::TimeLoop;
    std::fprintf(stderr, "error: out of memory %s\n",
                 in_loop ? "in the time loop (the run outgrew the estimate of `crater check`; "
                           "summary.json says so, --resume continues from the newest checkpoint)"
                         : "while setting up (reading the scenario, building the parts); "
                           "coarsen the resolution, lower output.memory_limit_fraction or free "
                           "memory");
    return in_loop ? kExitNumerical : kExitInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

// On several ranks, input and numerical errors are mostly found by every rank alike (the
// scenario, the collective checks): rank 0 says them, once. Any other failure is said by the
// rank that met it. Then the failing rank ends every rank (MPI_Abort with the exit code): a
// failure of one rank alone (rank 0 refusing --out, a file one rank cannot read) would leave
// the others waiting for it in their next collective, and a rank that returned normally would
// wait for them in MPI_Finalize.
int report_failure(const std::exception_ptr& failure, const std::string& out_dir_for_resume) {
  const auto& world = crater::parallel::Comm::world();
  if (world.size() == 1) return report_failure_here(failure, out_dir_for_resume, false);
  // Another rank than 0 with an error rank 0 may share: rank 0 is given the time to say it and
  // end the run; if it does not, the error was this rank's alone, and this rank says it.
  bool kept_quiet = false;
  int code = report_failure_here(failure, out_dir_for_resume, !world.root(), &kept_quiet);
  if (kept_quiet) {
    std::this_thread::sleep_for(std::chrono::seconds(2));
    code = report_failure_here(failure, out_dir_for_resume, false);
  }
  std::fflush(stderr);
  world.abort(code);
}

}  // namespace

int main(int argc, char** argv) {
  // Log lines (info, warnings) on stderr: stdout is for what a command prints (check's table).
  spdlog::set_default_logger(spdlog::stderr_color_mt("crater"));
  spdlog::set_pattern("crater: %^%l%$: %v");
  // MPI, when a launcher started this process (parallel/comm.hpp). On several ranks, `crater
  // run` spreads the parts over them (docs/distributed.md) and the root rank alone writes and
  // logs; the other ranks print only errors that are theirs alone.
  crater::parallel::Session mpi_session(argc, argv);
  const auto& world = crater::parallel::Comm::world();
  if (!world.root()) spdlog::set_level(spdlog::level::off);
  CommandLine cl;
  try {
    cl.app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return cl.app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return cl.app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return cl.app.exit(e);
  } catch (const CLI::ParseError& e) {
    cl.app.exit(e);
    return kExitInput;
  }

  std::string out_dir_for_resume;  // the run directory, for the interrupted message
  try {
    if (world.size() > 1 && !cl.app.got_subcommand("run"))
      throw InputError(
          {}, "command",
          fmt::format("only `crater run` runs on several MPI ranks (started on {})", world.size()));
    if (cl.app.got_subcommand("list")) return cmd_list();
    if (cl.app.got_subcommand("schema")) {
      fmt::print("{}", cl.markdown ? io::schema_markdown() : io::schema_text());
      return kExitOk;
    }
    if (cl.app.got_subcommand("report")) return crater::app::cmd_report(cl.report_opt);
    if (cl.app.got_subcommand("sweep")) return crater::app::cmd_sweep(cl.sweep->remaining());
    if (cl.app.got_subcommand("verify")) return crater::app::cmd_verify(cl.verify->remaining());
    if (cl.app.got_subcommand("check")) return cmd_check(cl.scenario, cl.sets, cl.level);
    if (cl.opt.quiet && world.root()) spdlog::set_level(spdlog::level::warn);
    resolve_run(cl, argc, argv);
    if (cl.ranks > 0) start_ranks(cl, argc, argv);
    out_dir_for_resume = cl.opt.out_dir.string();
    if (cl.scenario.empty())
      throw InputError({}, "scenario",
                       "a scenario file or bundled name (crater run SCENARIO), or --resume DIR");
    return cmd_run(cl.scenario, cl.sets, cl.level, cl.opt);
  } catch (...) {
    return report_failure(std::current_exception(), out_dir_for_resume);
  }
}
