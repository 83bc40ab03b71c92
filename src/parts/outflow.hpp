// domain.outflow = "remove" for particle parts: entities beyond the domain box leave the model
// at the end of a step, as hydrocodes deactivate material that leaves the mesh. The part marks
// the survivors, sums what the leaving ones carried (mass, and the energy that goes to
// Energies::eroded_j, so that the balance still closes), books it here and compacts its fields:
// the survivors keep their order (compaction in index order), so the numbers are the same for
// any thread count and after a restart.
#pragma once

#include <spdlog/spdlog.h>

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/index.hpp"
#include "core/types.hpp"
#include "fields/field_set.hpp"
#include "parallel/comm.hpp"
#include "parallel/parallel.hpp"
#include "parts/part.hpp"
#include "parts/state_archive.hpp"

namespace crater::parts {

/// True when x lies in the closed box [lo, hi] (a NaN coordinate is outside).
template <int D>
inline bool in_box(const Vec<D>& x, const Vec<D>& lo, const Vec<D>& hi) {
  for (int d = 0; d < D; ++d)
    if (!(x[d] >= lo[d] && x[d] <= hi[d])) return false;
  return true;
}

/// What leaving entities carried, summed with parallel::deterministic_sum: mass [kg] and
/// energy [J] (kinetic + internal, or whatever the part books as eroded).
struct Removed {
  Real mass_kg = 0, energy_j = 0;
  Removed& operator+=(const Removed& o) {
    mass_kg += o.mass_kg;
    energy_j += o.energy_j;
    return *this;
  }
};

/// The own entities of a removal (OutflowTally: a rank's, not its ghosts), counted over every
/// rank, and sums of what they carried by the reproducible sum: the same on every rank, for any
/// rank and thread count.
struct OutflowTally {
  std::vector<Index> own;  // this rank's own leaving entities, ascending
  Index count = 0;         // over every rank

  /// The sum of term(i) over every rank's own leaving entities. Collective.
  template <class Term>
  Real sum(const parallel::Comm& comm, Term&& term) const {
    std::vector<Real> terms(own.size());
    for (std::size_t q = 0; q < terms.size(); ++q)
      terms[q] = term(own[q]);
    return parallel::reproducible_sum(comm, std::span<const Real>(terms));
  }
};

/// The survivors' mask of the current removal and the ledger of everything removed so far
/// (summary.json's left_domain_* diagnostics; checkpointed).
class OutflowRemoval {
 public:
  /// Marks entity i of [0, n) as a survivor when inside(i); returns how many leave.
  template <class Inside>
  Index mark(Index n, Inside&& inside) {
    keep_.resize(at(n));
    return parallel::deterministic_sum<Index>(n, [&](Index i) {
      keep_[at(i)] = inside(i);
      return static_cast<Index>(!keep_[at(i)]);
    });
  }
  /// The leaving entities i of [0, n) with own(i) since the last mark(), counted over the ranks
  /// of `comm` (collective).
  template <class Own>
  OutflowTally tally(const parallel::Comm& comm, Index n, Own&& own) const {
    OutflowTally t;
    t.own = parallel::select(n, [&](Index i) { return !kept(i) && own(i); });
    t.count = static_cast<Index>(comm.sum(static_cast<std::int64_t>(t.own.size())));
    return t;
  }
  /// Whether entity i survives the removal last marked.
  bool kept(Index i) const { return keep_[at(i)] != 0; }
  /// The mask of the last mark() (1: survives), for compacting other per-entity arrays.
  std::span<const std::uint8_t> survivors() const { return keep_; }

  /// Books `count` leaving entities and what they carried; the part's first removal is logged
  /// (`entities`: "particles", "grains"; t_s: the time of the step; `why`: the setting that
  /// removes them).
  void book(const std::string& part, std::string_view entities, Real t_s, Index count,
            const Removed& removed, std::string_view why = "domain.outflow = \"remove\"") {
    if (count_ == 0)
      spdlog::info(
          "part '{}': {} leave the domain from t = {:.6g} s on and are removed "
          "({}; left_domain_* in summary.json)",
          part, entities, t_s, why);
    count_ += count;
    mass_kg_ += removed.mass_kg;
    energy_j_ += removed.energy_j;
  }

  /// Drops the entities that leave from f (the others keep their order); the new count.
  template <int D>
  Index compact(fields::FieldSet<D>& f) const {
    return f.compact(keep_);
  }

  Index count() const { return count_; }
  Real mass_kg() const { return mass_kg_; }
  /// Energy of the removed entities [J]: the part's Energies::eroded_j (or its share of it).
  Real energy_j() const { return energy_j_; }

  /// summary.json: left_domain_count, left_domain_mass_kg, left_domain_energy_j.
  void add_diagnostics(std::vector<Diagnostic>& d) const {
    d.push_back({"left_domain_count", static_cast<Real>(count_)});
    d.push_back({"left_domain_mass_kg", mass_kg_});
    d.push_back({"left_domain_energy_j", energy_j_});
  }

  /// The ledger in a checkpoint (the mask is scratch).
  void save(StateWriter& w) const {
    w.tag("outflow");
    w.value(count_);
    w.value(mass_kg_);
    w.value(energy_j_);
  }
  void load(StateReader& r) {
    r.tag("outflow");
    r.value(count_);
    r.value(mass_kg_);
    r.value(energy_j_);
  }

 private:
  std::vector<std::uint8_t> keep_;
  Index count_ = 0;
  Real mass_kg_ = 0, energy_j_ = 0;
};

}  // namespace crater::parts
