// Contacts between parts spread over MPI ranks (issue 29, docs/distributed.md "Contacts on
// ranks"): every contact runs on every rank on stand-ins of its two parts, assembled from the
// ranks' own entities in the order one rank holds them (Part::contact_layout; a solid's surface
// is its whole mesh's, Part::whole_contact_surface). The pairings then run as on one rank, and
// each part takes back the forces of its own entities, and the particles their contact state
// (the initial-penetration offsets).
//
// Two kinds of stand-in. A whole view (a surface; a particle part that is the smaller side of a
// particle contact; every particle part under multi-rate stepping) is gathered whole on every
// rank at every step (positions, velocities; masses, ids, radii and contact state only when
// some rank's have changed; the step limits take the views of the forces, for_limits). A
// particle part whose every contact is with a surface or a smaller particle part is viewed
// owner-computed (spread_zone.cpp): each rank searches its own particles of the contact zone
// against the other sides' whole views and sends each particle in contact to itself and to the
// owners of the bodies it touches, so rank r's view holds its own particles in contact and the
// others' that touch its own bodies, in the whole part's order. Every pair of an entity r owns
// is then in r's views in one rank's order: its forces, offsets and spring sums have one rank's
// bits on any rank count. The sums over pairs (diagnostics, history forces) count each pair on
// the rank owning its particle of that view and are reproducible sums over the ranks, and the
// step limits the smallest over the ranks (agree). What is left replicated (the whole views:
// every rank evaluates the pairs between two of them) is docs/distributed.md's next step.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "contact/candidates.hpp"
#include "contact/contact_zone.hpp"
#include "contact/pairing.hpp"
#include "contact/surface_filter.hpp"
#include "parallel/comm.hpp"
#include "parts/part.hpp"
#include "parts/whole_layout.hpp"

namespace crater::contact {

/// What a stand-in that does not step says when asked to (spread_coupling.cpp).
[[noreturn]] void refuse_stepping(const std::string& part, const char* what);

/// A part as a contact sees it, whole: its contact points or surface over the whole part, and
/// the forces the contacts hand it. It does not step.
template <int D>
class WholePart final : public parts::Part<D> {
 public:
  WholePart(std::string name, const char* method) : name_(std::move(name)), method_(method) {}

  const std::string& name() const override { return name_; }
  const char* method() const override { return method_; }
  Index count() const override { return static_cast<Index>(points_.position.size()); }

  std::optional<parts::ContactPoints<D>> contact_points() const override;
  std::optional<parts::ContactSurface<D>> contact_surface() const override { return surface_; }
  void add_contact_forces(const std::vector<Vec<D>>& force,
                          const std::vector<AxialVec<D>>& torque) override {
    force_ = force;
    torque_ = torque;
  }

  Real mass_kg() const override { refuse_stepping(name_, "mass_kg"); }
  parts::StableStep stable_step() const override { refuse_stepping(name_, "stable_step"); }
  void compute_forces(Real) override { refuse_stepping(name_, "compute_forces"); }
  std::optional<parts::Fault> check() const override { refuse_stepping(name_, "check"); }
  void advance(Real, Real) override { refuse_stepping(name_, "advance"); }
  void finish_step(Real) override { refuse_stepping(name_, "finish_step"); }
  parts::Energies energies() const override { refuse_stepping(name_, "energies"); }
  parts::Geometry<D> geometry() const override { refuse_stepping(name_, "geometry"); }
  std::vector<fields::FieldView> point_fields() const override {
    refuse_stepping(name_, "point_fields");
  }

  /// The fields of a particle view that may keep their whole values from the last assemble
  /// (bits of `kept` in assemble and of unchanged()).
  enum Kept : unsigned { kMassId = 1, kRadius = 2, kContactState = 4 };
  /// Of those fields, the ones whose values in this view are `part`'s for every entity this
  /// rank owns, bit for bit (0 for a surface, or a view not assembled for this layout's part).
  unsigned unchanged(const parts::Part<D>& part, const parts::WholeLayout& layout) const;
  /// The whole view of `part`, whose entities sit as `layout` says (collective): every field
  /// gathered but those `kept` (the same bits on every rank; the layout that of the last
  /// assemble), whose whole values stay.
  void assemble(const parallel::Comm& comm, const parts::Part<D>& part,
                const parts::WholeLayout& layout, unsigned kept = 0);
  /// The view of `part`'s particles that touch this rank's own entities of the other sides
  /// (owner-computed, collective): every rank sends each of its own particles to the ranks
  /// `to` names ((local entity, rank) pairs, ascending, itself included for its own that touch
  /// anything), and the view holds what it received, in the whole part's order, each marked
  /// whether it is this rank's own; with the whole part's count, lightest mass and largest
  /// contact radius (largest_radius_m, found by the caller).
  void assemble_zone(const parallel::Comm& comm, const parts::Part<D>& part,
                     const parts::WholeLayout& layout, const std::vector<std::pair<Index, int>>& to,
                     Real largest_radius_m);
  /// Particles in the view (a zone's: fewer than the whole part's).
  Index view_count() const { return static_cast<Index>(points_.position.size()); }
  /// The place in the whole part of the view's particle q.
  Index whole_index(Index q) const { return zone_ ? view_whole_[at(q)] : q; }
  /// The forces handed to this stand-in, given to `part` for the entities it holds, and its
  /// particles' contact state written back (a particle outside a zone's view: no force, and
  /// no face touched: offset -1, as the pairing leaves a particle that touches none).
  void hand_back(parts::Part<D>& part, const parts::WholeLayout& layout) const;
  /// Only the particles' contact state written back (a whole view's; multi-rate stepping).
  void hand_back_state(parts::Part<D>& part, const parts::WholeLayout& layout) const;

 private:
  std::string name_;
  const char* method_;
  bool is_points_ = false;
  struct Points {
    std::vector<Vec<D>> position, velocity;
    std::vector<Real> mass, radius, surface_offset, surface_overlap;
    std::vector<AxialVec<D>> angular_velocity;
    std::vector<std::int64_t> id;
    std::vector<char> own;  // a zone's view: this rank's own particle
    bool spins = false, offsets = false, ids = false;
  } points_;
  struct Nodes {
    std::vector<Vec<D>> position, velocity;
    std::vector<Real> mass;
  } nodes_;
  std::vector<Index> needed_of_;   // the surface's nodes that travel (Part::whole_surface_nodes)
  std::vector<char> needed_flag_;  // the same, per whole node
  std::optional<parts::ContactSurface<D>> surface_;
  // A contact zone's view: per local entity its place in the view (-1: not in it), and what
  // the view reports of the whole part.
  bool zone_ = false;
  std::vector<Index> view_of_local_;
  std::vector<Index> in_view_;  // the local entities in the view, ascending
  // hand_back's forces per local entity: zero but for the entities of `handed_`, the last
  // in_view_ handed back (kept so that a step zeroes those instead of every entity).
  mutable std::vector<Vec<D>> hand_force_;
  mutable std::vector<AxialVec<D>> hand_torque_;
  mutable std::vector<Index> handed_;
  std::vector<Index> view_whole_;  // per particle of the view, its place in the whole part
  Index whole_count_ = 0;
  Real whole_lightest_kg_ = 0, whole_largest_radius_m_ = 0;
  std::vector<Vec<D>> force_;
  std::vector<AxialVec<D>> torque_;
};

/// The stand-ins of the parts in contacts, at the indices of the parts (the others offer
/// nothing), refreshed at each evaluation.
template <int D>
class SpreadContacts {
 public:
  /// `sides`: the two parts of each contact (points, other), by index into `parts`; `zones`:
  /// whether a particle part may be viewed in its contact zone alone (zoned_view).
  SpreadContacts(const parallel::Comm& comm, const PartList<D>& parts,
                 std::vector<std::size_t> involved,
                 std::vector<std::pair<std::size_t, std::size_t>> sides,
                 std::vector<std::array<const SurfaceFilter<D>*, 2>> filters, bool zones);

  /// The stand-ins at the parts' current state (collective).
  const PartList<D>& refresh(const PartList<D>& parts);
  /// The stand-ins for the step limits (collective): those of the last refresh when no rank's
  /// part in a contact has changed what the limits read since (positions, masses, ids, the
  /// layout, a surface's nodes and faces), else refreshed. Between a step's contact forces and
  /// the next step's limits come the second half kick (velocities, which the limits do not
  /// read) and an SPH part's new contact radii, which the limits read only through the pairs
  /// of a stale load (pairing.hpp, load_stale), that is after a change of count, which
  /// refreshes. A step's limits then cost a comparison of what each rank holds and one
  /// maximum, not the gathers of every part's view.
  const PartList<D>& for_limits(const PartList<D>& parts);
  /// Refreshes so far, step limits that took the last refresh's views instead, and the
  /// particle views refreshed without their masses, ids and radii (kept: unchanged on every
  /// rank since).
  std::int64_t gathers() const { return gathers_; }
  std::int64_t reused() const { return reused_; }
  std::int64_t static_kept() const { return static_kept_; }
  /// Contact zones' views gathered, and the particles they held and their whole parts had, in
  /// sum over those gathers.
  std::int64_t zone_views() const { return zone_views_; }
  std::int64_t zone_particles() const { return zone_particles_; }
  std::int64_t zone_whole_particles() const { return zone_whole_; }
  /// Whether some part's view at the last refresh was its own particles and the others' that
  /// touch them (a contact zone's, which differs from rank to rank): then the contacts' sums
  /// and step limits are over the ranks (Coupling::finish, agree()).
  bool owner_computed() const { return owner_computed_; }
  /// The parts whose view at the last refresh was their contact zone, ascending.
  const std::vector<std::size_t>& zoned() const { return zoned_; }
  const parallel::Comm& comm() const { return comm_; }
  /// Each contact's limits, the smallest over the ranks (collective): on equal steps the
  /// smallest id, then the lowest rank, as StepSearch decides between bodies. `extra` (if
  /// given, as many numbers on every rank) travels with them and comes back as every rank's,
  /// rank after rank.
  void agree(std::vector<PairLimits>& limits, std::vector<Real>* extra = nullptr) const;
  /// Each part in a contact takes the forces of its entities from its stand-in.
  void hand_back(const PartList<D>& parts) const;
  /// Part k takes its particles' contact state from its (whole) stand-in.
  void hand_back_state(const PartList<D>& parts, std::size_t k) const;
  /// The stand-ins of the last refresh, and part k's layout then.
  const PartList<D>& views() const { return whole_; }
  const parts::WholeLayout& layout(std::size_t k) const { return *layout_[k]; }

 private:
  const parallel::Comm& comm_;
  std::vector<std::size_t> involved_;
  std::vector<std::pair<std::size_t, std::size_t>> sides_;
  std::vector<std::array<const SurfaceFilter<D>*, 2>> filters_;  // per contact, of each side
  bool zones_allowed_;
  bool owner_computed_ = false;
  std::vector<std::size_t> zoned_;  // the parts viewed by their zone at the last refresh
  PartList<D> whole_;
  /// Per part in a contact: this rank's own entities in its contact zone (per local entity), or
  /// nullopt when its view is whole (a surface, or a particle part that is the smaller side of
  /// a particle contact).
  /// Whether part k's view is its contact zone's: a particle part that is, in every contact
  /// it is in, against a surface or the larger side of a particle contact (by the whole
  /// counts; equal counts: the later part), so that the other side's bodies are few.
  bool zoned_view(const PartList<D>& parts, std::size_t k) const;
  /// Part k's own entities in its contact zone, per local entity (collective); r_max: its
  /// largest contact radius. The zone is found for a quarter more than each contact's reach and
  /// kept while no layout or surface has changed (a surface whose faces were listed again keeps
  /// it when they lie in its marked cells, faces_in_marked_cells) and every pair within reach
  /// now was within that then (each side has moved by less than the margin since): the view
  /// then keeps its particles, and the pairings their candidate lists (candidates.hpp).
  const std::vector<char>& zone_of(const PartList<D>& parts, std::size_t k, Real r_max);
  /// Of part k's own particles in its zone (`in_zone`, per local entity), the ranks each must
  /// go to (Zone::to): the search of each contact, run by this rank over its own particles
  /// against the other side's whole view, finds the pairs in contact, and a particle goes to
  /// this rank and to the owners of the bodies it touches (a face's nodes, the other part's
  /// particle). A non-finite position goes to this rank, whose pairing meets it as one rank's
  /// would. Every rank's view then holds every pair of its own entities, in one rank's order.
  void touching_of(const PartList<D>& parts, std::size_t k, const std::vector<char>& in_zone,
                   Real r_max);
  /// Each whole entity's owning rank of part k's layout at the last refresh.
  const std::vector<int>& owners_of(std::size_t k);
  struct Zone {
    bool valid = false;
    std::vector<char> in;  // per local entity
    std::vector<Index> whole_of_local, owned;
    std::vector<Vec<D>> x;  // this rank's own positions (per local entity)
    struct Other {
      std::uint64_t revision = 0;
      std::vector<Index> whole_of_local, owned;  // a particle part's layout
      std::vector<Vec<D>> x;                     // its own positions, or the whole surface's nodes
      Real reach = 0;                            // the reach the zone was found for
      std::optional<ZoneCells<D>> cells;         // a surface's marked cells
    };
    std::vector<Other> others;               // per contact of the part, in order
    std::vector<CrossCandidates<D>> search;  // touching_of's lists, per contact of the part
    std::vector<std::pair<Index, int>> to;   // (local entity, rank) to send, ascending
  };
  struct Owners {
    std::vector<Index> slot_of_gathered, owned_by_rank;  // the layout they were found for
    std::vector<int> rank;                               // per whole entity
  };
  std::vector<Owners> owners_;
  std::vector<Zone> zones_;
  static constexpr Real kZoneMargin = 0.25;
  std::vector<const parts::WholeLayout*> layout_;  // per part in a contact, of the last refresh
  /// What the step limits read of a part's local entities, as the last refresh saw it.
  struct Stamp {
    bool valid = false;
    std::vector<Index> whole_of_local, owned;
    std::vector<Vec<D>> position;
    std::vector<Real> mass;
    std::vector<std::int64_t> id;
    std::uint64_t revision = 0;
    void take(const parts::Part<D>& part, const parts::WholeLayout& layout);
    bool same(const parts::Part<D>& part, const parts::WholeLayout& layout) const;
    bool same_layout(const parts::WholeLayout& layout) const {
      return valid && layout.whole_of_local == whole_of_local && layout.owned == owned;
    }
  };
  std::vector<Stamp> stamp_;
  std::int64_t gathers_ = 0, reused_ = 0, static_kept_ = 0;
  std::int64_t zone_views_ = 0, zone_particles_ = 0, zone_whole_ = 0;
};

}  // namespace crater::contact
