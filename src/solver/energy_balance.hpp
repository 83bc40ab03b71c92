// The energy bookkeeping of a run: the total that is conserved, the relative balance error
// (history.csv energy_error, summary.json energy.balance_error) and the parts' energies summed
// in a fixed order (docs/theory.md "Energy balance").
#pragma once

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <vector>

#include "solver/part_names.hpp"

namespace crater::solver {
namespace fs = std::filesystem;

// Total energy: what the parts hold plus what left through damping, hourglass, contacts and
// erosion, minus the work done on them. Conserved up to discretisation error.
inline Real total_energy(const Energies& e) {
  return e.kinetic_j + e.internal_j + e.damping_j + e.hourglass_j + e.contact_j + e.eroded_j -
         e.external_work_j;
}

// The relative energy balance error: the drift of the total over the largest energy the run
// has held or been given, max over time of (kinetic + internal) and of the work done on it
// (LS-DYNA's energy ratio likewise divides by initial plus external work). The work matters for
// beds under gravity, whose kinetic and elastic energies stay small while gravity's work
// flows through them into dissipation.
struct EnergyTrack {
  Real initial_total = 0;
  Real scale = 0;  // the denominator of the relative error
  Real error(const Energies& e) {
    scale = std::max(
        {scale, std::abs(e.kinetic_j) + std::abs(e.internal_j), std::abs(e.external_work_j)});
    return scale > 0 ? (total_energy(e) - initial_total) / scale : 0.0;
  }
};

// Each part's energies, in part order, and their sum (the same additions in the same order).
template <int D>
std::vector<Energies> part_energies(const std::vector<std::unique_ptr<Part<D>>>& parts) {
  std::vector<Energies> per;
  per.reserve(parts.size());
  for (const auto& p : parts)
    per.push_back(p->energies());
  return per;
}
inline Energies sum_energies(const std::vector<Energies>& per) {
  Energies e;
  for (const Energies& x : per)
    e += x;
  return e;
}
template <int D>
Energies sum_energies(const std::vector<std::unique_ptr<Part<D>>>& parts) {
  return sum_energies(part_energies(parts));
}

}  // namespace crater::solver
