// The time loop of Algorithm 1 (simulation.hpp): a run from its start or a checkpoint to its
// end, as named steps of one class; the pieces it takes are step.hpp (one step, the stable
// step), run_outputs.hpp (frames, history, summary), run_state.hpp (loop state, guards,
// checkpoints) and energy_balance.hpp.
#include "solver/simulation.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <exception>
#include <limits>
#include <optional>
#include <tuple>

#include "contact/coupling.hpp"
#include "core/error.hpp"
#include "io/checkpoint/checkpoint.hpp"
#include "io/output/run_directory.hpp"
#include "parallel/parallel.hpp"
#include "solver/assembly.hpp"
#include "solver/energy_balance.hpp"
#include "solver/gauges.hpp"
#include "solver/memory_estimate.hpp"
#include "solver/multi_rate.hpp"
#include "solver/probes.hpp"
#include "solver/progress.hpp"
#include "solver/run_outputs.hpp"
#include "solver/run_state.hpp"
#include "solver/step.hpp"

namespace crater::solver {
namespace fs = std::filesystem;

namespace {

// SIGINT / SIGTERM: the loop finishes its step, writes a checkpoint and the outputs so far,
// and the program exits 130 (kExitInterrupted).
std::atomic<int> g_signal{0};
extern "C" void on_signal(int sig) {
  g_signal.store(sig);
}

struct SignalGuard {
  using Handler = void (*)(int);
  Handler old_int, old_term;
  SignalGuard() {
    g_signal.store(0);
    old_int = std::signal(SIGINT, on_signal);
    old_term = std::signal(SIGTERM, on_signal);
  }
  ~SignalGuard() {
    std::signal(SIGINT, old_int);
    std::signal(SIGTERM, old_term);
  }
};

template <int D>
class Run {
 public:
  Run(const io::Config& c, const RunOptions& opt)
      : c_(c),
        opt_(opt),
        wall_start_(std::chrono::steady_clock::now()),
        parts_((parallel::set_threads(opt.threads), build_parts<D>(c))),
        coupling_(contact_settings(c), parts_),
        probes_(c, parts_),  // the initial ground surface: before any step or resume
        gauges_(c, parts_),  // points resolved on the initial positions
        multi_rate_(c.time.safety_factor, c.time.multi_rate_max_ratio) {}

  RunResult go() {
    // On ranks, a resumed part is loaded whole on every rank, then spread.
    if (!opt_.restart.empty()) {
      resume();
      spread();
    } else {
      spread();
      start();
    }
    for (const auto& w : c_.warnings)
      spdlog::warn("{}", w);
    r_.threads = parallel::max_threads();
    r_.ranks = comm_.size();
    // On ranks a signal ends every rank at once (mpirun passes it on); a checkpoint on it is
    // for one rank.
    std::optional<SignalGuard> signals;
    if (comm_.size() == 1) signals.emplace();
    if (opt_.restart.empty()) {
      record_start();
      if (c_.time.multi_rate) start_multi_rate();
    }
    r_.steps = st_.steps;
    r_.first_step = st_.steps;
    // A summary from the start (status "running"), brought up to date at every checkpoint: a
    // run that is killed or runs out of disk still leaves one for `crater report` and --resume.
    summary("running", "");
    Progress progress(c_.end_time_s, opt_.quiet || !comm_.root(), st_.steps, st_.t,
                      comm_.size() > 1 ? std::function<std::string()>([&] { return load_note(); })
                                       : std::function<std::string()>());
    loop_start_s_ = elapsed();
    loop_start_mpi_s_ = comm_.seconds_in_mpi();
    set_activity(Activity::TimeLoop);  // an allocation that fails from here on exits 3 (main.cpp)
    loop(progress);
    if (c_.output.checkpoint_at_end) {
      // The last state, before the probes finish: --resume with a later end time extends it.
      out_->flush();
      if (c_.time.multi_rate) st_.rate_carried = multi_rate_.carried();
      write_checkpoint<D>(c_, manifest_.get(), st_, *out_, parts_, probes_);
    }
    stamp();
    progress.finish(r_.steps, st_.t, st_.dt);
    out_->flush();
    // Collective on ranks; the root writes, and its metrics are the run's.
    std::vector<Diagnostic> metrics = probes_.finish(parts_, opt_.out_dir, spread_over());
    if (manifest_ && fs::exists(opt_.out_dir / "surface_profile.csv"))
      manifest_->record("surface_profile.csv");
    summary("completed", "", metrics);
    return r_;
  }

 private:
  // Continues from opt_.restart: everything is checked before anything in the run directory
  // changes.
  void resume() {
    std::string payload;
    const io::CheckpointHeader h = io::read_checkpoint(opt_.restart, payload);
    parts::StateReader rd(payload, opt_.restart.string());
    if (h.dimension != D || h.scenario_hash != c_.state_hash)
      rd.fail(fmt::format(
          "it was written for another scenario (state hash {} vs {} of this one, after "
          "defaults and --set; resume with the same file and overrides: only "
          "scenario.end_time_s, time.max_steps, time.min_dt_s, the energy guard's keys and the "
          "[output] keys but interval_s may change{})",
          h.scenario_hash, c_.state_hash,
          c_.output.interval_given
              ? ""
              : "; output.interval_s is unset, so it follows the end time: set it to the run's, "
                "end_time_s / 20"));
    st_.load(rd);
    // The end time may have changed (a finished run extended): the next frame is the next
    // multiple of the interval, as if the run had always been going to this end time.
    st_.next_frame_t = frame_time(st_.frame);
    if (!(st_.t < c_.end_time_s - t_eps()))
      rd.fail(
          fmt::format("the run is already at t = {:.6g} s, not before scenario.end_time_s = "
                      "{:.6g} s (extend it with --set scenario.end_time_s=LATER)",
                      st_.t, c_.end_time_s));
    if (c_.time.multi_rate) {
      try {
        multi_rate_.restore(st_.rate_carried);
      } catch (const std::runtime_error& e) {
        rd.fail(e.what());
      }
    }
    std::vector<std::vector<std::pair<Real, std::string>>> pvd;
    std::uint64_t gauges_bytes = 0;
    const std::uint64_t history_bytes = Outputs<D>::load_pvd(rd, pvd, gauges_bytes);
    rd.tag("parts");
    if (rd.value<std::uint64_t>() != parts_.size()) rd.fail("it holds another number of parts");
    for (auto& p : parts_) {
      rd.tag(p->name());
      p->load_state(rd);
    }
    probes_.load(rd);
    if (!rd.done()) rd.fail("it holds more than this scenario's state");
    const fs::path from = run_dir_of_checkpoint(opt_.restart);
    const bool same_dir = same_directory(from, opt_.out_dir);
    // On ranks, the root alone reads and writes the run directory (another rank reading
    // history.csv while the root rewrites it would see it cut short), and its failure stops
    // every rank.
    std::string history, gauge_rows;
    std::exception_ptr failed;
    if (comm_.root()) {
      try {
        history = rows_at_checkpoint(opt_, from, "history.csv", history_bytes, same_dir);
        if (!gauges_.empty())
          gauge_rows = rows_at_checkpoint(opt_, from, "gauges.csv", gauges_bytes, same_dir);
        if (!same_dir) io::prepare_new_run_directory(opt_.out_dir, opt_.force);
        manifest_ = std::make_unique<io::RunManifest>(opt_.out_dir);
        if (!same_dir) carry_frames(from, *manifest_, pvd);
        // The command as continued (its --set may extend the run): a later --resume takes it.
        io::write_run_command(opt_.out_dir, opt_.command);
        manifest_->record(io::kCommandName);
      } catch (...) {
        failed = std::current_exception();
      }
    }
    if (comm_.size() > 1 && comm_.max(failed ? 1.0 : 0.0) > 0 && !failed)
      throw InputError({}, "--resume", "rank 0 could not continue the run directory");
    if (failed) std::rethrow_exception(failed);
    const bool fresh_history = history.empty();
    out_ = std::make_unique<Outputs<D>>(c_, manifest_.get(), opt_.out_dir, &comm_, parts_,
                                        history_columns(parts_, coupling_, probes_),
                                        std::move(history), gauges_header(), std::move(gauge_rows));
    if (fresh_history) out_->flush();
    out_->restore_pvd(std::move(pvd));
    spdlog::info("resumed from {} at step {}, t = {:.6g} s", opt_.restart.string(), st_.steps,
                 st_.t);
  }

  // A new run: the initial state's forces, the checks that need them, the run directory.
  void start() {
    for (auto& p : parts_) {
      p->expect_frame();         // frame 0 (record_start)
      p->compute_forces(st_.t);  // rates and sound speeds of the initial state
    }
    coupling_.apply(parts_, 0);
    const StepLimit<D> lim = smallest_stable_step(parts_, &coupling_, Real(1));
    check_fixed_step(c_, lim);
    check_step_count(c_, lim.allowed_s);
    for (const auto& w : check_output_cadence(c_, parts_, lim.allowed_s, opt_.out_dir))
      spdlog::warn("{}", w);
    if (comm_.root()) {  // on ranks, the root alone writes
      io::prepare_new_run_directory(opt_.out_dir, opt_.force);
      manifest_ = std::make_unique<io::RunManifest>(opt_.out_dir);
      manifest_->record(io::kCommandName);
      io::write_run_command(opt_.out_dir, opt_.command);
    }
    out_ = std::make_unique<Outputs<D>>(c_, manifest_.get(), opt_.out_dir, &comm_, parts_,
                                        history_columns(parts_, coupling_, probes_), std::string(),
                                        gauges_header());
  }

  // On ranks, the progress line's load balance: the part whose heaviest rank is furthest above
  // the mean (Part::load_ratio: at its last look at its cuts; no communication).
  std::string load_note() const {
    std::size_t worst = 0;
    for (std::size_t k = 1; k < parts_.size(); ++k)
      if (parts_[k]->load_ratio() > parts_[worst]->load_ratio()) worst = k;
    if (parts_.empty()) return {};
    return fmt::format("  {} ranks, load max/mean {:.2f} ({})", comm_.size(),
                       parts_[worst]->load_ratio(), parts_[worst]->name());
  }

  // The ranks the parts are spread over, for the probes' collective maxima; null on one rank.
  const parallel::Comm* spread_over() const { return comm_.size() > 1 ? &comm_ : nullptr; }

  // Several MPI ranks: every part is spread over them (Part::distribute). Checkpoints are written
  // by the root as one rank would (Part::save_state gathers): they resume on one rank.
  void spread() {
    if (comm_.size() == 1) return;
    for (auto& p : parts_) {
      p->distribute(comm_);
      if (fields::BusyClock* busy = p->busy_clock()) busy->by_time = c_.domain.balance_by_time;
    }
    // Multi-rate stepping keeps per-particle sums over a part's step: whole views only.
    coupling_.spread(comm_, parts_, /*zones=*/!c_.time.multi_rate);
  }

  // On ranks, cuts by measured time (domain.balance, fields/balance.hpp): each spread part's
  // compute seconds of the step just taken (its stages less the time in MPI's calls), and the
  // contacts' in equal shares to the parts viewed by their contact zone, whose own particles
  // there are this rank's share of the contacts' work. Every rank adds one step to every part.
  void note_busy() {
    if (comm_.size() == 1 || !c_.domain.balance_by_time) return;
    auto compute = [](const StageClock::Tally& t) { return t.s - t.mpi_s; };
    const double contacts = compute(clock_.contacts) - busy_seen_contacts_s_;
    busy_seen_contacts_s_ += contacts;
    const std::vector<std::size_t> zoned = coupling_.zoned_parts();
    busy_seen_s_.resize(parts_.size(), 0.0);
    for (std::size_t k = 0; k < parts_.size(); ++k) {
      double s = 0;
      if (k < clock_.parts.size()) {
        s = compute(clock_.parts[k]) - busy_seen_s_[k];
        busy_seen_s_[k] += s;
      }
      if (std::find(zoned.begin(), zoned.end(), k) != zoned.end())
        s += contacts / static_cast<double>(zoned.size());
      if (fields::BusyClock* busy = parts_[k]->busy_clock()) busy->add(s);
    }
  }

  // The energies at t = 0 (the balance's reference, each part's for the energy guard), the
  // first frame and history row.
  void record_start() {
    const std::vector<Energies> per = part_energies(parts_);
    st_.e0 = sum_energies(per);
    st_.track = EnergyTrack{total_energy(st_.e0), 0};
    st_.err = st_.track.error(st_.e0);
    for (const Energies& x : per)
      st_.part_total0_j.push_back(total_energy(x));
    out_->frame(parts_, st_.t, "000000");
    if (!gauges_.empty()) out_->gauges(gauges_.row(0, st_.t, parts_, spread_over()));
    out_->history(0, st_.t, 0, st_.e0, total_energy(st_.e0), st_.err,
                  history_values(per, coupling_, probes_, parts_, spread_over()));
    st_.next_frame_t = frame_time(1);
  }

  // The steps to the end time; a numerical failure writes the last state (<part>_failure.vtu)
  // and a failed summary, a failed write (a full disk) a failed summary when there is room.
  void loop(Progress& progress) {
    const Real t_eps = this->t_eps();
    try {
      while (st_.t < c_.end_time_s - t_eps &&
             (c_.time.max_steps == 0 || r_.steps < c_.time.max_steps)) {
        Real dt = 0;
        bool at_frame = false;
        if (c_.time.multi_rate) {
          std::tie(dt, at_frame) = multi_rate_cycle(t_eps);
        } else {
          std::tie(dt, at_frame) = next_step(t_eps);
          if (at_frame)
            for (auto& p : parts_)
              p->expect_frame();
          advance_stage(parts_, st_.t, dt, &clock_);
          st_.t = at_frame ? st_.next_frame_t : st_.t + dt;
          ++r_.steps;
          st_.steps = r_.steps;
          finish_step_stages(parts_, coupling_, st_.t, dt, &clock_);
        }
        note_busy();
        StageClock::time(probes_s_, [&] { probes_.after_step(parts_, st_.t, spread_over()); });
        const bool last = st_.t >= c_.end_time_s - t_eps;
        StageClock::time(output_s_, [&] {
          record_step(dt, at_frame, last);
          progress.update(r_.steps, st_.t, dt);
          checkpoint_or_stop(last);
        });
      }
    } catch (const NumericalError& ne) {
      // The state now in memory is the last one whose forces were finite.
      out_->frame(parts_, st_.t, "failure");
      stamp();
      out_->flush();
      summary("failed", ne.what());
      throw;
    } catch (const Interrupted&) {
      throw;
    } catch (const std::exception& ex) {
      // The newest complete checkpoint is where --resume continues from.
      stamp();
      try {
        summary("failed", std::string(ex.what()) + "; resume with: crater run --resume " +
                              opt_.out_dir.string());
      } catch (const std::exception&) {
        // No room even for the summary: the one of the last checkpoint stays.
      }
      throw;
    }
  }

  // The time of output frame k: k intervals, rounded to 15 significant decimal digits (a relative
  // change below 1e-15, well inside t_eps), or the end time if that is sooner (clip_to_end). The
  // rounding makes k x 1e-5 = 6.000000000000001e-05 the 6e-5 an end time is written as, so a run
  // that ended there and is extended lands its steps as one run to the later end time does.
  Real frame_time(Index k, bool clip_to_end = true) const {
    const Real exact = c_.output.interval_s * static_cast<Real>(k);
    const Real rounded = std::strtod(fmt::format("{:.14e}", exact).c_str(), nullptr);
    return clip_to_end ? std::min(rounded, c_.end_time_s) : rounded;
  }

  std::string gauges_header() const { return gauges_.empty() ? std::string() : gauges_.header(); }

  // Two times closer than this are the same output time. A fraction of the interval, not of the
  // end time: a run extended to a later end time lands its steps as one run there would.
  Real t_eps() const { return 1e-12 * c_.output.interval_s; }

  // The next step's length, and whether it lands on an output time (shortened to it).
  std::pair<Real, bool> next_step(Real t_eps) {
    const Real t = st_.t;
    const StepLimit<D> lim = smallest_stable_step(
        parts_, &coupling_, c_.time.fixed_dt_s ? Real(1) : c_.time.safety_factor);
    Real dt = c_.time.fixed_dt_s ? *c_.time.fixed_dt_s : lim.allowed_s;
    // Nothing limits the step when no part has live entities left (every element of a solid
    // eroded): go straight to the next output time.
    if (!c_.time.fixed_dt_s && lim.dt_s == std::numeric_limits<Real>::infinity())
      dt = st_.next_frame_t - t;
    // A fixed step accepted at t = 0 may exceed the limit later (an expanding charge speeds
    // up); going on would be unstable, so stop with the limiting part named.
    if (c_.time.fixed_dt_s && *c_.time.fixed_dt_s > lim.dt_s)
      throw NumericalError(lim.part, lim.detail.entity_id, t,
                           fmt::format("the fixed time step {:.4g} s exceeds the stable step "
                                       "{:.4g} s ({}); lower time.fixed_dt_s or unset it",
                                       *c_.time.fixed_dt_s, lim.dt_s, lim.detail.reason));
    if (!(dt > 0) || !std::isfinite(dt))
      throw NumericalError(lim.part.empty() ? "?" : lim.part, lim.detail.entity_id, t,
                           fmt::format("stable time step is {} ({})", lim.dt_s, lim.detail.reason));
    below_min_dt(dt, lim);
    // Land exactly on output times and on the end time.
    bool at_frame = false;
    if (t + dt >= st_.next_frame_t - t_eps) {
      dt = st_.next_frame_t - t;
      at_frame = true;
    }
    st_.dt = dt;
    st_.dt_min = std::min(st_.dt_min, dt);
    st_.dt_max = std::max(st_.dt_max, dt);
    return {dt, at_frame};
  }

  // time.min_dt_s: a step below it ends the run, naming what limits it.
  void below_min_dt(Real dt, const StepLimit<D>& lim) const {
    if (!c_.time.min_dt_s || !(dt < *c_.time.min_dt_s)) return;
    throw NumericalError(lim.part.empty() ? "?" : lim.part, lim.detail.entity_id, st_.t,
                         fmt::format("the time step {:.4g} s fell below time.min_dt_s = {:.4g} s "
                                     "(stable step {:.4g} s: {})",
                                     dt, *c_.time.min_dt_s, lim.dt_s, lim.detail.reason));
  }

  // Multi-rate stepping: the plan of the first cycle from the initial state, and the share of
  // the initial contact forces of the parts whose contacts are evaluated at a finer step.
  void start_multi_rate() {
    const RatePlan plan = multi_rate_.plan(parts_, coupling_);
    st_.rate_ratio = plan.ratio;
    st_.rate_base_step_s = plan.h;
    st_.part_steps.assign(parts_.size(), 0);
    const Real t_eps = this->t_eps();
    multi_rate_.start(parts_, coupling_, make_cycle(plan, st_.t, st_.next_frame_t, t_eps).ratio);
  }

  // One multi-rate cycle (multi_rate.hpp) from the plan in st_; its base step and whether it
  // ends at an output time. The plan of the next cycle is decided at its end.
  std::pair<Real, bool> multi_rate_cycle(Real t_eps) {
    const RateCycle cy =
        make_cycle({st_.rate_ratio, st_.rate_base_step_s}, st_.t, st_.next_frame_t, t_eps);
    if (!(cy.h > 0) || !std::isfinite(cy.h)) {
      const StepLimit<D> lim = smallest_stable_step(parts_, &coupling_, c_.time.safety_factor);
      throw NumericalError(lim.part.empty() ? "?" : lim.part, lim.detail.entity_id, st_.t,
                           fmt::format("stable time step is {} ({})", lim.dt_s, lim.detail.reason));
    }
    // The plan's step, not the cycle's (shortened to land on an output time).
    if (c_.time.min_dt_s && st_.rate_base_step_s < *c_.time.min_dt_s)
      below_min_dt(st_.rate_base_step_s,
                   smallest_stable_step(parts_, &coupling_, c_.time.safety_factor));
    // The output time after this cycle's end, as record_step will set it; after the run's last
    // cycle, the one a run to a later end time would have next (the plan decided here is in the
    // checkpoint that extends the run).
    const bool run_ends = cy.t_end >= c_.end_time_s - t_eps;
    const Real frame_after = !cy.at_frame ? st_.next_frame_t
                             : run_ends   ? frame_time(st_.frame + 1, false)
                                          : frame_time(st_.frame + 1);
    auto decide = [&] {
      const RatePlan plan = multi_rate_.plan(parts_, coupling_);
      st_.rate_ratio = plan.ratio;
      st_.rate_base_step_s = plan.h;
      return make_cycle(plan, cy.t_end, frame_after, t_eps).ratio;
    };
    multi_rate_.cycle(cy, parts_, coupling_, clock_, decide, st_.part_steps);
    st_.t = cy.t_end;
    ++r_.steps;
    st_.steps = r_.steps;
    st_.dt = cy.h;
    st_.dt_min = std::min(st_.dt_min, cy.h);
    st_.dt_max = std::max(st_.dt_max, cy.h);
    return {cy.h, cy.at_frame};
  }

  // A history row every history_every steps, at frames and at the end (with the energy
  // guard), and the frame.
  void record_step(Real dt, bool at_frame, bool last) {
    if (r_.steps % c_.output.history_every == 0 || at_frame || last) {
      const std::vector<Energies> per = part_energies(parts_);
      const Energies e = sum_energies(per);
      st_.err = st_.track.error(e);
      out_->history(r_.steps, st_.t, dt, e, total_energy(e), st_.err,
                    history_values(per, coupling_, probes_, parts_, spread_over()));
      guard_energy(c_, st_, per, parts_);
    }
    if (!gauges_.empty() && (r_.steps % c_.output.gauges_every_steps == 0 || at_frame || last))
      out_->gauges(gauges_.row(r_.steps, st_.t, parts_, spread_over()));
    if (at_frame) {
      out_->frame(parts_, st_.t, fmt::format("{:06d}", st_.frame));
      ++st_.frame;
      st_.next_frame_t = frame_time(st_.frame);
      out_->flush();
    }
  }

  // A checkpoint when one is due (by steps or wall-clock time) or a signal came; a signal then
  // ends the run (Interrupted: exit 130) with an "interrupted" summary.
  void checkpoint_or_stop(bool last) {
    const int sig = g_signal.load();
    // By wall-clock time, the root's clock decides for every rank.
    bool by_time = c_.output.checkpoint_every_s > 0 &&
                   elapsed() - last_checkpoint_s_ >= c_.output.checkpoint_every_s;
    if (comm_.size() > 1 && c_.output.checkpoint_every_s > 0)
      by_time = comm_.max(comm_.root() && by_time ? 1.0 : 0.0) > 0;
    const bool due = (c_.output.checkpoint_every_steps > 0 &&
                      r_.steps % c_.output.checkpoint_every_steps == 0) ||
                     by_time;
    if ((due || sig != 0) && !last) {
      out_->flush();
      if (c_.time.multi_rate) st_.rate_carried = multi_rate_.carried();
      write_checkpoint<D>(c_, manifest_.get(), st_, *out_, parts_, probes_);
      stamp();
      if (sig == 0) summary("running", "");
      last_checkpoint_s_ = elapsed();
    }
    if (sig != 0 && !last) {
      stamp();
      summary("interrupted", fmt::format("stopped by signal {} at step {}; resume with: crater "
                                         "run --resume {}",
                                         sig, r_.steps, opt_.out_dir.string()));
      throw Interrupted(sig, r_.steps, st_.t);
    }
  }

  void summary(const std::string& status, const std::string& message,
               const std::vector<Diagnostic>& metrics = {}) {
    const Energies now = sum_energies(parts_);
    EnergyTrack track = st_.track;  // a copy: the scale it keeps must not move between rows
    const Real err = status == "failed" ? st_.err : track.error(now);
    write_summary(
        c_,
        SummaryInputs{manifest_.get(), opt_.command, r_, st_.dt_min, st_.dt_max, st_.e0, now, err},
        parts_, status, message, &coupling_, metrics);
  }

  double elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
  }
  void stamp() {
    r_.time_s = st_.t;
    r_.wall_s = elapsed();
    r_.loop_s = r_.wall_s - loop_start_s_;
    r_.loop_mpi_s = comm_.seconds_in_mpi() - loop_start_mpi_s_;
    RunResult::TimeByPart& tp = r_.time_by_part;
    tp.parts_s.clear();
    tp.parts_mpi_s.clear();
    double accounted = clock_.contacts.s + probes_s_ + output_s_;
    for (std::size_t k = 0; k < parts_.size(); ++k) {
      const StageClock::Tally t = k < clock_.parts.size() ? clock_.parts[k] : StageClock::Tally{};
      tp.parts_s.emplace_back(parts_[k]->name(), t.s);
      tp.parts_mpi_s.push_back(t.mpi_s);
      accounted += t.s;
    }
    r_.steps_by_part.clear();
    for (std::size_t k = 0; k < st_.part_steps.size() && k < parts_.size(); ++k)
      r_.steps_by_part.emplace_back(parts_[k]->name(), st_.part_steps[k]);
    tp.contacts_s = clock_.contacts.s;
    tp.contacts_mpi_s = clock_.contacts.mpi_s;
    tp.probes_s = probes_s_;
    tp.output_s = output_s_;
    tp.other_s = std::max(0.0, r_.loop_s - accounted);
  }

  const io::Config& c_;
  const RunOptions& opt_;
  const parallel::Comm& comm_ = parallel::Comm::world();
  const std::chrono::steady_clock::time_point wall_start_;
  std::vector<std::unique_ptr<Part<D>>> parts_;
  contact::Coupling<D> coupling_;
  Probes<D> probes_;
  Gauges<D> gauges_;
  LoopState st_;
  std::unique_ptr<io::RunManifest> manifest_;
  std::unique_ptr<Outputs<D>> out_;
  RunResult r_;
  double loop_start_s_ = 0;
  double loop_start_mpi_s_ = 0;  // seconds_in_mpi() then
  double last_checkpoint_s_ = 0;
  MultiRate<D> multi_rate_;  // time.multi_rate: each part at its own step
  StageClock clock_;         // the parts' stages and the contacts, for run.time_by_part_s
  // The compute seconds of clock_ already added to the parts' BusyClocks (note_busy).
  std::vector<double> busy_seen_s_;
  double busy_seen_contacts_s_ = 0;
  double probes_s_ = 0;  // the probes after each step
  double output_s_ = 0;  // history rows, frames, progress, checkpoints
};

template <int D>
RunResult run(const io::Config& c, const RunOptions& opt) {
  return Run<D>(c, opt).go();
}

template <int D>
std::vector<PartReport> check(const io::Config& c) {
  auto parts = build_parts<D>(c, Settling::CachedOnly);
  contact::Coupling<D> coupling(contact_settings(c), parts);
  const Gauges<D> gauges(c, parts);  // refuses an unknown field or entity, as run does
  std::vector<PartReport> reports;
  for (auto& p : parts) {
    p->compute_forces(0);
    PartReport r{p->name(), p->method(), p->count(), p->mass_kg(), p->stable_step(), {}};
    for (const Diagnostic& d : p->diagnostics())
      if (d.name == "solid_fraction" || d.name == "bulk_density_kg_m3")
        r.bed.push_back(d);
      else if (d.name == "packing_unsettled")
        r.unsettled = true;
    reports.push_back(r);
  }
  if (!coupling.empty()) {
    const StableStep s = coupling.stable_step(parts);
    reports.push_back({"contacts", "contact", static_cast<Index>(c.contacts.size()), 0, s, {}});
  }
  const StepLimit<D> lim = smallest_stable_step(parts, &coupling, Real(1));
  check_fixed_step(c, lim);
  check_step_count(c, lim.allowed_s);
  for (const auto& w : check_output_cadence(c, parts, lim.allowed_s, {}))
    spdlog::warn("{}", w);
  return reports;
}

}  // namespace

std::vector<PartReport> check_scenario(const io::Config& config) {
  set_activity(Activity::Setup);
  require_memory(config);  // before any part is built
  return config.dimension == 2 ? check<2>(config) : check<3>(config);
}

RunResult run_scenario(const io::Config& config, const RunOptions& options) {
  set_activity(Activity::Setup);
  require_memory(config);  // before any part is built or the run directory touched
  return config.dimension == 2 ? run<2>(config, options) : run<3>(config, options);
}

}  // namespace crater::solver
