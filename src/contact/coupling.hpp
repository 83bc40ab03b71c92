// Contacts between parts (paper section III-D; DESIGN section 3 "Coupling"): penalty forces,
// equal and opposite, found with the shared neighbour search.
//
//   particle-surface (sph-fem, dem-fem): each particle (a disk/sphere of its contact radius r)
//     against the nearest face of the solid's surface. Closest point c on the face, outward
//     normal n_f; the particle centre at signed distance s = (x - c).n_f. In front of the face
//     (s >= 0) the normal is n = (x - c)/|x - c| (rounded edges and corners) and the overlap
//     delta = r - |x - c|; behind it (-r < s < 0, the centre has crossed, and c is the foot
//     of x on the face: x projects onto it) n = n_f and delta = r - s. A centre behind the
//     plane of a face that it projects beside has not crossed that face (a particle on a
//     plate's top next to its edge is behind the side face's plane): it is treated as in
//     front. Each particle takes the face of largest overlap (ties: the lowest face).
//     Stiffness k = s_p K A^2 / V of the face's element (LS-DYNA's segment stiffness; K bulk
//     modulus, A face area, V element volume; s_p = penalty_scale).
//     Penetration found at first touch is not pushed out: a particle that starts touching with
//     an overlap deeper than its approach over the step, |v_n| dt, (one laid overlapping at
//     t = 0; one a face appears around when the element beside it erodes) keeps the excess as
//     an offset, the force acts on delta - offset, and the offset shrinks to delta as the
//     particle backs out (LS-DYNA's treatment of initial penetrations in eroding contacts).
//     The same holds for a particle already in contact whose overlap jumps by more than
//     2 |v_n| dt in one step: its face eroded and the face behind it (an element deeper)
//     took over; the jump joins the offset. Without this the penalty spring releases energy it
//     never stored. One offset and the last overlap per particle
//     (parts::ContactPoints::surface_offset, surface_overlap): a particle meets one solid's
//     surface at a time.
//   surface-surface (fem-fem): penalty node-to-segment, both ways: every node of either part's
//     surface (with mass) against the faces of the other's. A node x is in contact with a face
//     when it lies behind it, s = (x - c).n_f < 0 with c the closest point of the face, by less
//     than half the face's size, and c is its foot (x - c along n_f to 1 % of the face's size:
//     the node projects onto the face); of those faces the one of smallest depth. n = n_f,
//     delta = -s, k = s_p min(K A^2 / V of the face's element, the largest of the node's own
//     faces) (LS-DYNA's rule for two segment stiffnesses), and the forces as below with the
//     node as the particle (no radius, no spin, no initial-penetration offset).
//   particle-particle (sph-dem): an SPH particle (radius = half its spacing) against every
//     grain it overlaps, delta = r_1 + r_2 - d, k = s_p E r_2 (3D) or s_p E (2D, per metre),
//     E the grain's Young's modulus.
// Force on the particle (the other side gets its opposite, spread over the face's nodes with
// the weights of c):
//     F_n = max(0, k delta - c_n v_n),   c_n = 2 xi sqrt(k m*),  m* = m_1 m_2 / (m_1 + m_2)
//     F_t = -min(mu F_n, c_t |v_t|) v_t / |v_t|,   c_t = sqrt(k m*) / 2
// with v the velocity of the particle's contact point (spin included for grains) relative to
// the other side's (the face's interpolated node velocity), v_n = v.n, v_t = v - v_n n. The
// tangential force is Coulomb friction regularised by a dashpot at low slip speed (c_t is a
// quarter of critical: a rolling grain's tangential mass is down to m*/3.5): no history is kept, so
// the forces depend only on the current state (bit-identical restarts need nothing stored here). A
// grain also gets the moment (-r n) x F_t.
//
// Energy: the parts book the work the contact forces do on them (trapezoidal, like their
// external work) as -contact_j; the sum over both sides is what the penalty springs store plus
// what damping and friction dissipate.
//
// Step limit: each pair is a spring k between the masses, omega = sqrt(k_max / m*) with k_max
// over the contact's faces (grains) and m* the reduced mass of its lightest particle and its
// lightest face node (sph-dem: the code takes the lighter of its lightest particle and its
// lightest grain, min(m_1, m_2), not their m*); dt <= 1/(2 omega), a quarter of the
// damped spring's stability limit, so that an impact spans a dozen steps and its energy is
// booked to ~0.1 % (see spring_step in penalty.hpp). A body pressed by several springs at
// once is stiffer than any one of them: per face node the springs of the pairs in contact are
// summed with the node's weights in them (sum k w), per particle over its pairs (sum k), and
// omega = sqrt(sum / m) of the body limits too (a face node left with a quarter of an
// element's mass where its neighbour eroded may carry three grains). The sums come from the
// last apply(), or from a search of the current state when there is none (the first step after
// a resume, `crater check`, particles removed): the same numbers either way. Each side's limit
// (its own bodies) and the pair's (the reduced mass) are kept apart (PairLimits), with each
// side's lightest body on the stiffest spring alone: multi-rate stepping (solver/multi_rate.hpp)
// holds each part to its side's limits and the finer part to the pair's.
//
// The code: one class per pairing, each in its own file over the parts' state views
// (parts::ContactPoints, parts::ContactSurface) behind pairing.hpp's interface:
// particle_surface (sph-fem, dem-fem), surface_surface (fem-fem), particle_particle (sph-dem);
// the penalty law in penalty.hpp, the face geometry in face_geometry.hpp. registry.cpp picks a
// contact's pairing from what its two parts offer (a new pairing: its file and one line there).
// Coupling owns the pairings in scenario order and runs them in that order, so that every sum
// is taken in the same order whatever the thread count. The solver builds the ContactSettings
// (settings.hpp) from the scenario; contact/ includes nothing of io/, the methods or solver/.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "contact/pairing.hpp"
#include "contact/settings.hpp"
#include "parts/part.hpp"

namespace crater::contact {

template <int D>
class SpreadContacts;  // spread_coupling.hpp

/// On ranks: how many times the contacts' views were gathered, how many step limits took those
/// of the forces instead (SpreadContacts::for_limits), how many whole particle views were
/// gathered without their masses, ids and radii (kept), and the contact zones' views: how many,
/// with how many particles in sum, of how many in their whole parts.
struct ViewCounts {
  std::int64_t gathers = 0, reused_for_limits = 0, static_kept = 0;
  std::int64_t zone_views = 0, zone_particles = 0, zone_whole_particles = 0;
};

template <int D>
class Coupling {
 public:
  /// The contacts `contacts` (in scenario order) between `parts`.
  Coupling(const std::vector<ContactSettings>& contacts, const PartList<D>& parts);

  ~Coupling();

  bool empty() const { return pairings_.empty(); }
  /// On ranks: the counts of its views (ViewCounts); none on one rank.
  std::optional<ViewCounts> view_counts() const;

  /// The parts were spread over the ranks of `comm` (Part::distribute): from now on every
  /// contact is evaluated on every rank over stand-ins of its parts, whole or owner-computed
  /// (spread_coupling.hpp), and apply(), evaluate(), stable_step() and limits() are collective.
  /// `zones`: a particle part may be viewed in its contact zone alone (not under multi-rate
  /// stepping, whose sums follow every particle of the whole part).
  void spread(const parallel::Comm& comm, const PartList<D>& parts, bool zones = true);

  /// Smallest stable step over the contacts, with the contact named in `reason`.
  parts::StableStep stable_step(const PartList<D>& parts) const;

  /// Forces of the current state, handed to every part in a contact (after compute_forces);
  /// dt_s is the step just taken (0 for the initial state).
  void apply(const PartList<D>& parts, Real dt_s);
  /// apply() in two calls: the forces (collective on ranks), then handed to the parts. Between
  /// them the contacts' parts may finish their own force stage (Part::end_forces), which writes
  /// nothing a contact reads.
  void compute(const PartList<D>& parts, Real dt_s);
  void hand_over(const PartList<D>& parts);
  /// Whether the contacts run over ranks' views (spread_coupling.hpp): their calls are then
  /// collective, made by every rank's main thread at the same point of the step.
  bool on_ranks() const { return spread_ != nullptr; }
  /// On ranks: the parts whose contact view at the last evaluation was their contact zone
  /// (owner-computed, spread_coupling.hpp), ascending; none on one rank.
  std::vector<std::size_t> zoned_parts() const;

  /// The contacts in scenario order: how many, the parts of contact c (its first part, then
  /// its second), and each one's step limits apart (pairing.hpp's PairLimits).
  std::size_t size() const { return pairings_.size(); }
  std::array<std::size_t, 2> sides(std::size_t c) const {
    return {pairings_[c]->points(), pairings_[c]->other()};
  }
  std::vector<PairLimits> limits(const PartList<D>& parts) const;

  /// Multi-rate stepping (solver/multi_rate.hpp): the forces of the contacts `which`
  /// (ascending) at the current state, contact c last evaluated dt_s[c] ago, each into its own
  /// out[c] (per part, sized for its two parts only); nothing is handed to the parts but the
  /// particles' contact state. On ranks the forces are over the whole parts, in one rank's
  /// order (collective).
  void evaluate(const PartList<D>& parts, const std::vector<std::size_t>& which,
                const std::vector<Real>& dt_s, std::vector<ContactForces<D>>& out);
  /// Multi-rate stepping: the parts as the last evaluate() saw them, whose contact points'
  /// count and ids index its forces: `parts` on one rank, the whole stand-ins on ranks.
  const PartList<D>& seen(const PartList<D>& parts) const;
  /// Multi-rate stepping: part k's contact forces indexed as evaluate()'s, for its last half
  /// kick (add_contact_forces) or, `next`, its next step's first (set_next_contact_forces);
  /// on ranks each rank's part takes those of the entities it holds.
  void hand_to(const PartList<D>& parts, std::size_t k, const std::vector<Vec<D>>& force,
               const std::vector<AxialVec<D>>& torque, bool next) const;

  /// Per contact: pairs in contact, deepest overlap and total normal force at the last apply().
  std::vector<parts::Diagnostic> diagnostics() const;

  /// history.csv columns: per contact the total force on its second part (the surface, or the
  /// grains) at the last apply(), force_<contact>_x, _y[, _z] [N] (N/m in 2D). The totals over
  /// the pairs are reproducible sums (pairing.hpp, ContactSums): the same bits for any pair
  /// order, thread or rank count.
  std::vector<std::string> history_columns() const;
  std::vector<Real> history_values() const;

 private:
  std::vector<std::unique_ptr<Pairing<D>>> pairings_;
  std::unique_ptr<SpreadContacts<D>> spread_;  // on ranks
  std::vector<std::size_t> involved_;          // parts in any contact, ascending
  ContactForces<D> forces_;                    // apply()'s per-part buffers, kept from step to step
  std::vector<std::size_t> all_;               // every contact's index
  // On ranks, owner-computed: the limits agreed at the last apply(), and the count of views
  // gathered then (SpreadContacts::gathers; -1: none).
  std::vector<PairLimits> limits_;
  std::int64_t limits_at_ = -1;

  /// The totals of the contacts `which` from their pairs (on ranks collective).
  void finish(const PartList<D>& on, const std::vector<std::size_t>& which);

  /// Sizes out's zeroed forces (and torques, for rotating particles) for part k's bodies;
  /// `track`: out is forces_ on one rank, whose particle parts' touched particles are kept.
  void size_for(const PartList<D>& parts, std::size_t k, ContactForces<D>& out, bool track) const;
};

}  // namespace crater::contact
