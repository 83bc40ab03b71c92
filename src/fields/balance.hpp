// How a spread particle part weighs the ranks' loads when it decides to cut again (issue 29,
// docs/distributed.md "The decomposition", scenario key domain.balance):
// - by a cost model ("count"): a grain weighs 1, an SPH particle 1 + its pairs;
// - by measured time ("time", the default): each rank's compute time for the part over a window
//   of at least kTimeWindowSteps steps (the part's stages less the time in MPI's calls, and a
//   share of the contacts' when the part's contact view is a zone), gathered at a rebuild. When
//   the busiest rank's time exceeds the mean by kRebalanceTolerance, the cuts are made again,
//   each entity weighted by its model weight times its rank's time per unit of model weight (as
//   LAMMPS's `fix balance ... weight time`). A window's time is noisy (±8 % over 60 steps of
//   paper-3d's soil on 2 ranks): windows of 20 steps and a 5 % tolerance chased the noise, the
//   cuts made again 6 times in 1 ms, against 1–2 times with these. The cuts then follow the
//   machine's clock; the results do not (the cuts decide only who computes what).
#pragma once

#include "core/types.hpp"

namespace crater::fields {

/// A rank's load above the mean beyond which the cuts are made again (by model or time).
inline constexpr Real kRebalanceTolerance = 0.10;
/// The fewest steps a window of measured time must span before it decides anything: shorter
/// windows are noise (the first steps' cold caches, a burst of the machine's other work).
inline constexpr Index kTimeWindowSteps = 100;

/// A spread part's measured load since its cuts were last made (by_time: domain.balance =
/// "time"). The time loop adds each step's seconds (Simulation); the part reads it at a rebuild
/// and starts a new window when it cuts again. The steps are the same on every rank, so every
/// rank decides alike whether a window is long enough.
struct BusyClock {
  bool by_time = false;
  double busy_s = 0;
  Index steps = 0;
  void add(double s) {
    busy_s += s;
    ++steps;
  }
  void restart() {
    busy_s = 0;
    steps = 0;
  }
};

}  // namespace crater::fields
