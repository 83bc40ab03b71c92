// Contacts between parts spread over MPI ranks (issue 29, docs/distributed.md "Contacts on
// ranks"): every rank evaluates every contact on whole stand-ins of its two parts, assembled from
// the ranks' own entities in the order one rank holds them (Part::contact_layout; a solid's
// surface is its whole mesh's, Part::whole_contact_surface). The pairings then run as on one
// rank, over the same numbers in the same order, and every sum they take (a particle's force
// from its faces, a node's from its particles, the step limits, the diagnostics and history
// forces) has one rank's bits on any rank count. Each part takes back the forces of the entities
// it holds, and the particles their contact state (the initial-penetration offsets).
//
// The cost is a replicated contact stage: every rank gathers the whole contact view of each part
// in a contact (positions, velocities, masses, radii, spins, offsets, ids; a solid's nodes) at
// every step (once: the step limits take the views of the forces, for_limits; the masses, ids,
// radii and contact state only when some rank's have changed), and evaluates every pair. Right for
// the scenes the tests run and for the paper's 2D scene at its demo level; what scales instead
// (views of the contact zone alone, then each rank the pairs of its own entities) is
// docs/distributed.md's next step.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

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
  /// The forces handed to this stand-in, given to `part` for the entities it holds, and its
  /// particles' contact state written back.
  void hand_back(parts::Part<D>& part, const parts::WholeLayout& layout) const;

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
  std::vector<Vec<D>> force_;
  std::vector<AxialVec<D>> torque_;
};

/// The stand-ins of the parts in contacts, at the indices of the parts (the others offer
/// nothing), refreshed at each evaluation.
template <int D>
class SpreadContacts {
 public:
  SpreadContacts(const parallel::Comm& comm, const PartList<D>& parts,
                 std::vector<std::size_t> involved);

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
  /// Each part in a contact takes the forces of its entities from its stand-in.
  void hand_back(const PartList<D>& parts) const;

 private:
  const parallel::Comm& comm_;
  std::vector<std::size_t> involved_;
  PartList<D> whole_;
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
};

}  // namespace crater::contact
