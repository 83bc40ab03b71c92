// Contacts between parts spread over MPI ranks (issue 29, docs/distributed.md "Contacts on
// ranks"): every rank evaluates every contact on whole stand-ins of its two parts, assembled from
// the ranks' own entities in the order one rank holds them (Part::contact_layout; a solid's
// surface is its whole mesh's, Part::whole_contact_surface). The pairings then run as on one
// rank, over the same numbers in the same order, and every sum they take (a particle's force
// from its faces, a node's from its particles, the step limits, the diagnostics and history
// forces) has one rank's bits on any rank count. Each part takes back the forces of the entities
// it holds, and the particles their contact state (the initial-penetration offsets).
//
// The cost is a replicated contact stage: every rank gathers the contact view of each part in a
// contact (positions, velocities, masses, radii, spins, offsets, ids; a solid's nodes) at every
// step (once: the step limits take the views of the forces, for_limits; the masses, ids, radii
// and contact state only when some rank's have changed) and evaluates every pair. A particle
// part whose every contact is with a surface or a smaller particle part is viewed in its contact
// zone alone (spread_zone.cpp): the particles that can touch the other side, and of those only
// the ones each rank's search over its own finds in contact travel; a subsequence of the whole
// part in its order, which holds every pair in contact. What scales further (each
// rank the pairs of its own entities, the forces on others' sent back per pair) is
// docs/distributed.md's next step.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "contact/candidates.hpp"
#include "contact/pairing.hpp"
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
  /// The view of `part`'s particles in its contact zone alone (`in_zone`: per local entity,
  /// this rank's own that are), in the whole part's order, with the whole part's count, lightest
  /// mass and largest contact radius (largest_radius_m, found by the caller) (collective).
  void assemble_zone(const parallel::Comm& comm, const parts::Part<D>& part,
                     const parts::WholeLayout& layout, const std::vector<char>& in_zone,
                     Real largest_radius_m);
  /// Particles in the view (a zone's: fewer than the whole part's).
  Index view_count() const { return static_cast<Index>(points_.position.size()); }
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
    bool spins = false, offsets = false, ids = false;
  } points_;
  struct Nodes {
    std::vector<Vec<D>> position, velocity;
    std::vector<Real> mass;
  } nodes_;
  std::optional<parts::ContactSurface<D>> surface_;
  // A contact zone's view: per local entity its place in the view (-1: not in it), and what
  // the view reports of the whole part.
  bool zone_ = false;
  std::vector<Index> view_of_local_;
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
                 std::vector<std::pair<std::size_t, std::size_t>> sides, bool zones);

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
  bool zones_allowed_;
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
  /// kept while no layout or surface has changed and every pair within reach now was within
  /// that then (each side has moved by less than the margin since): the view then keeps its
  /// particles, and the pairings their candidate lists (candidates.hpp).
  const std::vector<char>& zone_of(const PartList<D>& parts, std::size_t k, Real r_max);
  /// Of part k's own particles in its zone (`in_zone`, per local entity), those a pairing of
  /// its contacts may find in contact with the other side's whole view, per local entity: the
  /// search of each contact run by this rank over its own particles alone (the other side is
  /// whole on every rank), so that only those travel. A superset of the particles in contact
  /// (a surface's faces unfiltered by a contact's group; a non-finite position counts), which
  /// is all the view needs: it is a subsequence of the whole part in its order that holds every
  /// pair in contact.
  const std::vector<char>& touching_of(const PartList<D>& parts, std::size_t k,
                                       const std::vector<char>& in_zone, Real r_max);
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
    };
    std::vector<Other> others;               // per contact of the part, in order
    std::vector<CrossCandidates<D>> search;  // touching_of's lists, per contact of the part
    std::vector<char> touching;              // per local entity
  };
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
