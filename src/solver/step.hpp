// One step of the time loop (Algorithm 1) over all parts, and the step it may take: the
// stable limits of the parts and the contacts, the user's fixed step held to them. The time
// loop (simulation.cpp) takes these; tests/unit/solver drives them with stub parts.
#pragma once

#include <fmt/format.h>
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "contact/coupling.hpp"
#include "core/error.hpp"
#include "io/scenario/config.hpp"
#include "parallel/comm.hpp"
#include "parallel/parallel.hpp"
#include "solver/part_names.hpp"

namespace crater::solver {
namespace fs = std::filesystem;

template <int D>
struct StepLimit {
  Real dt_s = std::numeric_limits<Real>::infinity();       // the limit as its part states it
  Real allowed_s = std::numeric_limits<Real>::infinity();  // the step it allows (safety applied)
  std::string who;   // "part 'x'" or the contact; empty when nothing limits the step
  std::string part;  // the limiting part's name, or "contact"
  StableStep detail;
};

/// The limit that allows the smallest step under `safety_factor` (1: the limits as stated,
/// which a fixed step must respect).
template <int D>
StepLimit<D> smallest_stable_step(const std::vector<std::unique_ptr<Part<D>>>& parts,
                                  const contact::Coupling<D>* coupling, Real safety_factor) {
  StepLimit<D> lim;
  auto consider = [&](const StableStep& s, std::string who, std::string part) {
    if (s.allowed_s(safety_factor) < lim.allowed_s)
      lim = {s.dt_s, s.allowed_s(safety_factor), std::move(who), std::move(part), s};
  };
  for (const auto& p : parts)
    consider(p->stable_step(), "part '" + p->name() + "'", p->name());
  if (coupling && !coupling->empty())
    consider(coupling->stable_step(parts), "the contacts", "contact");
  return lim;
}

// The user's fixed step must not exceed the stable limit (READING-NOTES: the paper's 1 us
// does); the error names the limiting part.
template <int D>
void check_fixed_step(const io::Config& c, const StepLimit<D>& lim) {
  if (!c.time.fixed_dt_s || lim.who.empty()) return;
  if (*c.time.fixed_dt_s > lim.dt_s)
    throw InputError(c.time.fixed_dt_where, "time.fixed_dt_s",
                     fmt::format("fixed step {:.4g} s exceeds the stable limit {:.4g} s of {} "
                                 "({}, entity {}); use at most {:.4g} s or unset it",
                                 *c.time.fixed_dt_s, lim.dt_s, lim.who, lim.detail.reason,
                                 lim.detail.entity_id, lim.dt_s));
}

/// Wall time spent in each part's stages and in the contacts (summary.json's
/// run.time_by_part_s), and of it, in MPI's calls (run.time_by_rank_s); a reading of the clock
/// around each stage costs tens of nanoseconds.
struct StageClock {
  /// One stage's time, and the part of it in MPI's calls (waiting for other ranks, moving bytes).
  struct Tally {
    double s = 0, mpi_s = 0;
  };
  std::vector<Tally> parts;  // per part, scenario order
  Tally contacts;

  using Clock = std::chrono::steady_clock;
  /// Runs f() and adds its wall time to `into`.
  template <class F>
  static void time(double& into, F&& f) {
    const Clock::time_point start = Clock::now();
    f();
    into += std::chrono::duration<double>(Clock::now() - start).count();
  }
  /// Runs f() and adds its wall time and its time in MPI's calls to `into`.
  template <class F>
  static void time(Tally& into, F&& f) {
    const double mpi_s = parallel::Comm::world().seconds_in_mpi();
    time(into.s, std::forward<F>(f));
    into.mpi_s += parallel::Comm::world().seconds_in_mpi() - mpi_s;
  }
  /// The same, or f() alone when there is no clock (`into` null).
  template <class F>
  static void time(Tally* into, F&& f) {
    if (into)
      time(*into, std::forward<F>(f));
    else
      f();
  }
  /// Where part k's time goes on `clock`, or nowhere.
  static Tally* part_of(StageClock* clock, std::size_t k) {
    return clock ? &clock->part(k) : nullptr;
  }
  Tally& part(std::size_t k) {
    if (parts.size() <= k) parts.resize(k + 1);
    return parts[k];
  }
};

/// The first stage of a step from t to t + dt: every part advances (half kick, drift), in
/// scenario order. finish_step_stages follows once the time is moved on to t + dt.
template <int D>
void advance_stage(const std::vector<std::unique_ptr<Part<D>>>& parts, Real t, Real dt,
                   StageClock* clock = nullptr) {
  for (std::size_t k = 0; k < parts.size(); ++k)
    StageClock::time(StageClock::part_of(clock, k), [&] { parts[k]->advance(t, dt); });
}

/// The forces of the new state part by part and the contacts between parts (finish_step_stages).
/// The parts' heaviest loops (Part::begin_forces' blocks) share the threads with the contacts,
/// which read nothing the blocks write: the main thread evaluates the contacts while the other
/// threads take the blocks, then joins them (parallel::alongside); every part then ends its
/// stage, and the contacts' forces are handed over. The same bits as the parts' whole force
/// stages one after the other, then the contacts. On ranks the contacts' calls are collective,
/// made by each rank's main thread: the blocks run first, then the contacts. A part's time on
/// `clock` is its own calls' and, of the time shared with the contacts, its blocks' share of
/// what the contacts did not take.
template <int D>
void force_stages(const std::vector<std::unique_ptr<Part<D>>>& parts,
                  contact::Coupling<D>& coupling, Real t_new, Real dt,
                  StageClock* clock = nullptr) {
  auto part_clock = [&](std::size_t k) { return StageClock::part_of(clock, k); };
  StageClock::Tally* contacts = clock ? &clock->contacts : nullptr;
  // first[k]: part k's first block in the numbering over all parts.
  std::vector<Index> first(parts.size() + 1, 0);
  for (std::size_t k = 0; k < parts.size(); ++k) {
    Index blocks = 0;
    StageClock::time(part_clock(k), [&] { blocks = parts[k]->begin_forces(t_new); });
    first[k + 1] = first[k] + blocks;
  }
  const Index blocks = first.back();
  auto block = [&](Index b) {
    const auto k = static_cast<std::size_t>(std::upper_bound(first.begin(), first.end(), b) -
                                            first.begin() - 1);
    parts[k]->force_block(b - first[k]);
  };
  // A block is a few dozen pairs: worth a fork from parallel_min() / 16 of them (Cost::heavy).
  if (coupling.on_ranks() || !parallel::forks(blocks, parallel::Cost::heavy)) {
    for (std::size_t k = 0; k < parts.size(); ++k)
      StageClock::time(part_clock(k), [&] {
        parallel::for_each_block(
            first[k + 1] - first[k], 1, [&](Index b, Index) { block(first[k] + b); },
            parallel::Cost::heavy);
      });
    for (std::size_t k = 0; k < parts.size(); ++k)
      StageClock::time(part_clock(k), [&] { parts[k]->end_forces(); });
    StageClock::time(contacts, [&] { coupling.apply(parts, dt); });
    return;
  }
  double shared_s = 0, contacts_s = 0;
  const double mpi_s = parallel::Comm::world().seconds_in_mpi();
  StageClock::time(shared_s, [&] {
    parallel::alongside(
        blocks, 4, [&] { StageClock::time(contacts_s, [&] { coupling.compute(parts, dt); }); },
        block);
  });
  if (clock) {
    clock->contacts.s += contacts_s;
    clock->contacts.mpi_s += parallel::Comm::world().seconds_in_mpi() - mpi_s;
    for (std::size_t k = 0; k < parts.size(); ++k)
      clock->part(k).s += (shared_s - contacts_s) * static_cast<double>(first[k + 1] - first[k]) /
                          static_cast<double>(blocks);
  }
  for (std::size_t k = 0; k < parts.size(); ++k)
    StageClock::time(part_clock(k), [&] { parts[k]->end_forces(); });
  StageClock::time(contacts, [&] { coupling.hand_over(parts); });
}

/// The rest of the step, at t_new = t + dt (given, so that a step lands exactly on an output
/// time): the forces of the new state part by part, the contacts between parts (force_stages),
/// every part checked (a fault throws NumericalError naming the first failing part, before any
/// part finishes the step), then every part finishes the step (second half kick). Parts in
/// scenario order at every stage.
template <int D>
void finish_step_stages(const std::vector<std::unique_ptr<Part<D>>>& parts,
                        contact::Coupling<D>& coupling, Real t_new, Real dt,
                        StageClock* clock = nullptr) {
  auto part_clock = [&](std::size_t k) { return StageClock::part_of(clock, k); };
  force_stages(parts, coupling, t_new, dt, clock);
  for (std::size_t k = 0; k < parts.size(); ++k)
    StageClock::time(part_clock(k), [&] {
      if (auto fault = parts[k]->check())
        throw NumericalError(parts[k]->name(), fault->entity_id, t_new, fault->what);
    });
  for (std::size_t k = 0; k < parts.size(); ++k)
    StageClock::time(part_clock(k), [&] { parts[k]->finish_step(dt); });
}

}  // namespace crater::solver
