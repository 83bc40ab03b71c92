// The interface every pairing of two parts implements (particle_surface.hpp,
// particle_particle.hpp, surface_surface.hpp), and what they share: the contact's settings and
// name, its diagnostics and history force, the per-body spring sums that limit the step, and
// the search for the smallest step over all contacts. The physics is in coupling.hpp's header
// comment; registry.hpp picks the pairing of a contact from what its two parts offer.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "contact/settings.hpp"
#include "contact/surface_filter.hpp"
#include "core/index.hpp"
#include "core/types.hpp"
#include "parallel/comm.hpp"
#include "parts/part.hpp"

namespace crater::contact {

/// The solver's parts, in scenario order (a contact names two of them by index).
template <int D>
using PartList = std::vector<std::unique_ptr<parts::Part<D>>>;

/// The smallest stable step over the contacts found so far, and what sets it. A candidate
/// replaces it only when strictly smaller (the first one found wins ties); its reason is
/// formatted only then.
struct StepSearch {
  parts::StableStep best;
  StepSearch() { best.dt_s = std::numeric_limits<Real>::infinity(); }
  /// entity: the body's id (-1: none in particular). On equal steps the smallest id wins,
  /// whatever order the bodies come in (the order a rank holds them in: docs/distributed.md).
  template <class Reason>
  void consider(Real dt, Index entity, Reason&& reason) {
    if (dt < best.dt_s ||
        (dt == best.dt_s && entity >= 0 && (best.entity_id < 0 || entity < best.entity_id))) {
      best.dt_s = dt;
      best.entity_id = entity;
      best.reason = reason();
    }
  }
};

/// A contact's step limits, apart: `pair` bounds the step at which the contact is evaluated
/// (its stiffest spring between its lightest bodies), `points` and `other` the step of each
/// side's part (its bodies pressed by several springs, each with its own mass). One step for
/// all parts obeys the three; under multi-rate stepping each side keeps to its own.
struct PairLimits {
  StepSearch pair, points, other;
};

/// Forces (and torques on rotating particles) of the contacts per part, per particle or per
/// node of a surface; empty for parts in no contact.
template <int D>
struct ContactForces {
  std::vector<std::vector<Vec<D>>> force;
  std::vector<std::vector<AxialVec<D>>> torque;
  /// Coupling's own buffers keep, per particle part, the particles given a force since the
  /// buffers were last zeroed (`marked` flags them; `touched` lists them, first write first),
  /// so that zeroing them and handing them over need not visit every particle. Empty for a
  /// part not tracked (a surface's nodes; buffers that are not Coupling's).
  std::vector<std::vector<Index>> touched;
  std::vector<std::vector<std::uint8_t>> marked;

  /// Notes that particle i of part k is given a force (a no-op for an untracked part).
  void touch(std::size_t k, Index i) {
    if (k >= marked.size() || marked[k].empty()) return;
    std::uint8_t& m = marked[k][at(i)];
    if (m) return;
    m = 1;
    touched[k].push_back(i);
  }
};

/// What a contact reports of its last apply() (or one direction of it). The sums over the pairs
/// are reproducible (parallel::ReproducibleSum): finish() adds the terms kept per pair, so that
/// their bits do not depend on the pairs' order nor on how the ranks share them.
template <int D>
struct ContactSums {
  Index active = 0;                        // pairs in contact
  Real max_overlap_m = 0;                  // deepest overlap [m]
  Real normal_force_n = 0;                 // total normal force [N] (N/m in 2D)
  Vec<D> force_on_other = Vec<D>::Zero();  // total force on the contact's second part
  /// Per pair counted: its normal force and its force on the second part, until finish().
  std::vector<std::array<Real, D + 1>> terms;

  /// Counts one pair in contact: its overlap [m], normal force [N] and force on the second part.
  void add(Real overlap_m, Real normal_n, const Vec<D>& on_other) {
    ++active;
    max_overlap_m = std::max(max_overlap_m, overlap_m);
    std::array<Real, D + 1>& t = terms.emplace_back();
    t[0] = normal_n;
    for (int k = 0; k < D; ++k)
      t[static_cast<std::size_t>(k + 1)] = on_other[k];
  }
  /// Adds another direction's pairs.
  void append(const ContactSums& other) {
    active += other.active;
    max_overlap_m = std::max(max_overlap_m, other.max_overlap_m);
    terms.insert(terms.end(), other.terms.begin(), other.terms.end());
  }
  /// No pairs (the terms' storage kept).
  void clear() {
    active = 0;
    max_overlap_m = 0;
    normal_force_n = 0;
    force_on_other = Vec<D>::Zero();
    terms.clear();
  }
};

/// What the totals of `sums` need of every rank's pairs beside their levels (pairing.cpp): per
/// contact its pairs, deepest overlap and each term's largest magnitude (the bounds of the
/// reproducible sums), which the ranks gather.
template <int D>
std::vector<Real> sums_head(const std::vector<ContactSums<D>*>& sums);
/// The totals of each of `sums` from its terms. On ranks (`comm`), each rank holds the pairs it
/// counts of every contact, and the totals are over every rank's (collective: one reduction
/// for all of them); `heads`: every rank's sums_head, rank after rank. One rank, or null
/// `comm`: over its own (`heads` null).
template <int D>
void finish_sums(const std::vector<ContactSums<D>*>& sums, const parallel::Comm* comm,
                 const std::vector<Real>* heads);

/// The springs summed per body of one side [N/m], with the bodies that carry any. A contact
/// touches a few hundred of a part's thousands of bodies, so a reset zeroes those alone and the
/// step limit looks at those alone (the sums of all others are zero).
class BodyLoads {
 public:
  std::size_t size() const { return value_.size(); }
  Real operator[](std::size_t i) const { return value_[i]; }
  /// All zero for n bodies.
  void reset(std::size_t n) {
    if (value_.size() != n) {
      value_.assign(n, 0);
    } else {
      for (Index i : loaded_)
        value_[at(i)] = 0;
    }
    loaded_.clear();
  }
  /// Adds a spring k >= 0 to body i.
  void add(Index i, Real k) {
    Real& v = value_[at(i)];
    if (v == 0 && k != 0) loaded_.push_back(i);
    v += k;
  }
  /// The bodies with a nonzero sum, in the order they were loaded.
  const std::vector<Index>& bodies() const { return loaded_; }
  /// The same, ascending.
  const std::vector<Index>& loaded() const {
    std::sort(loaded_.begin(), loaded_.end());
    return loaded_;
  }

 private:
  std::vector<Real> value_;
  mutable std::vector<Index> loaded_;
};

/// The springs summed per body over the pairs in contact [N/m]: sum k w per face node of a
/// surface, sum k per particle (or surface node with its own hits), for each side.
struct SpringSums {
  BodyLoads points, other;
  bool known = false;
};

/// One contact between two parts: `points` (the particles, or the first surface) and `other`
/// (the surface, the grains, or the second surface).
template <int D>
class Pairing {
 public:
  Pairing(const ContactSettings& settings, std::size_t points, std::size_t other,
          const PartList<D>& parts);
  virtual ~Pairing() = default;
  Pairing(const Pairing&) = delete;
  Pairing& operator=(const Pairing&) = delete;

  std::size_t points() const { return points_; }
  std::size_t other() const { return other_; }
  const std::string& name() const { return name_; }

  /// This contact's step limits.
  virtual void limit_step(const PartList<D>& parts, PairLimits& limits) const = 0;
  /// Adds this contact's forces of the current state to `out` (dt_s: the step just taken).
  virtual void apply(const PartList<D>& parts, Real dt_s, ContactForces<D>& out) = 0;

  /// Pairs in contact, deepest overlap and total normal force at the last apply().
  void add_diagnostics(std::vector<parts::Diagnostic>& d) const;
  /// force_<name>_x, _y[, _z]: the total force on `other` at the last apply() [N] (N/m in 2D).
  void add_history_columns(std::vector<std::string>& cols) const;
  void add_history_values(std::vector<Real>& v) const;
  /// The faces of side 0 (`points`) or 1 (`other`) this contact sees (surface_of).
  const SurfaceFilter<D>& filter(int side) const { return filter_[at(side)]; }
  /// The sums of the last apply(), whose totals finish_sums() gives (Coupling, after every
  /// pairing has run).
  ContactSums<D>& sums() { return last_; }

 protected:
  /// Zeroes the diagnostics and sizes the spring sums for n_points and n_other bodies; the
  /// caller then adds to both.
  void restart(std::size_t n_points, std::size_t n_other);
  /// Offers each side the step of its lightest body on the contact's stiffest spring alone,
  /// the other side held (a body about to touch: its side's limit before the spring sums
  /// below know of it). Never below the pair's limit (the reduced mass is the smaller).
  void limit_sides(PairLimits& limits, Real k_max, Real m_points, Real m_other) const;
  /// Offers the step limit of every body of one side pressed by several springs at once:
  /// dt = spring_step(sum k, m) of each, named by id (`id`: the particles' ids; null: the index
  /// is the id, as for nodes); on equal steps the smallest id.
  void limit_by_summed_springs(StepSearch& search, const BodyLoads& load,
                               const std::vector<Real>& mass, const char* what,
                               const std::vector<std::int64_t>* id = nullptr) const;
  /// Whether the spring sums must be found afresh for bodies of these counts: none since the
  /// last apply(), or bodies were removed since (the sums are per body index).
  bool load_stale(std::size_t n_points, std::size_t n_other) const {
    return !load_.known || load_.points.size() != n_points || load_.other.size() != n_other;
  }
  /// Fills the spring sums afresh, without forces: sized for n_points and n_other bodies, then
  /// add(h) for each contact h of `found`.
  template <class Found, class Add>
  void measure(std::size_t n_points, std::size_t n_other, const Found& found, Add add) const {
    load_.points.reset(n_points);
    load_.other.reset(n_other);
    for (const auto& h : found)
      add(h);
    load_.known = true;
  }

  /// The surface of side 0 (`points`) or 1 (`other`) as this contact sees it: the part's own,
  /// or its faces in the contact's group (surface_filter.hpp). None: the part has no surface.
  std::optional<parts::ContactSurface<D>> surface_of(const PartList<D>& parts, int side) const {
    const auto s = parts[side == 0 ? points_ : other_]->contact_surface();
    if (!s) return s;
    return filter_[at(side)].view(*s);
  }

  ContactSettings settings_;
  std::size_t points_, other_;
  std::array<SurfaceFilter<D>, 2> filter_;  // of side 0 (points) and 1 (other)
  std::string name_;
  ContactSums<D> last_;      // of the last apply()
  mutable SpringSums load_;  // from the last apply() (load_.known) or found afresh
};

/// Builds a pairing of type P (the factories of registry.cpp's table).
template <class P, int D>
std::unique_ptr<Pairing<D>> make_pairing_of(const ContactSettings& settings, std::size_t points,
                                            std::size_t other, const PartList<D>& parts) {
  return std::make_unique<P>(settings, points, other, parts);
}

/// Smallest positive mass of a node on the surface's faces [kg] (infinity when none).
template <int D>
Real lightest_face_node(const parts::ContactSurface<D>& surf);

/// Smallest particle mass [kg] (infinity when none), exact for any thread count.
template <int D>
Real lightest_particle(const parts::ContactPoints<D>& pts);

}  // namespace crater::contact
