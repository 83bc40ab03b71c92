// The contact zone of a particle part on ranks (contact/spread_coupling.hpp, docs/distributed.md
// "Contacts on ranks"): the particles that can touch another part's bodies this step, a superset
// of those within a pairing's reach of them. The other side's points mark the cells of a lattice
// anchored at the origin whose cells are at least the reach across; a particle is in the zone when
// its cell or one next to it is marked. A particle's membership depends on its own position and on
// the marked cells alone, which every rank holds alike, so the zone is the same set of particles
// for any number of ranks.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <algorithm>
#include <limits>

#include "core/index.hpp"
#include "core/types.hpp"
#include "parallel/comm.hpp"
#include "parts/part.hpp"
#include "parts/whole_layout.hpp"

namespace crater::contact {

/// The largest contact radius of a spread particle part, from each rank's own particles
/// (collective; exact in any order).
template <int D>
Real whole_largest_radius(const parallel::Comm& comm, const parts::ContactPoints<D>& p,
                          const parts::WholeLayout& layout) {
  Real r = -std::numeric_limits<Real>::infinity();
  for (const Index i : layout.owned)
    r = std::max(r, (*p.radius)[at(i)]);
  return comm.max(r);
}

template <int D>
class ZoneCells {
 public:
  using Key = std::array<std::int64_t, D>;

  /// Cells for a pairing of this reach [m]; none (no particle is near) when the reach is not
  /// positive and finite.
  explicit ZoneCells(Real reach_m);

  /// Marks the cell of a point of the other side (non-finite points mark nothing).
  void occupy(const Vec<D>& x);
  /// Ready for near(): the cells marked here, with those of every rank when `comm` is given
  /// (collective: the other side's points are spread over the ranks), and their neighbours.
  void seal(const parallel::Comm* comm);
  /// Whether a particle at x may be within the reach of a marked point (a non-finite position
  /// is: the pairing then meets it as it would on one rank).
  bool near(const Vec<D>& x) const;
  /// Whether x lies in a marked cell itself (after seal; a non-finite x does not).
  bool marks(const Vec<D>& x) const;

 private:
  Key key_of(const Vec<D>& x) const;

  Real cell_m_ = 0;
  bool usable_ = false;
  std::vector<Key> occupied_;
  // The marked cells and their neighbours: a bitmap over their box when it is compact, else
  // the sorted keys.
  Key lo_{}, extent_{};
  std::vector<char> bitmap_;
  std::vector<Key> dilated_;
  bool dense_ = false;
};

/// Whether a zone found for a surface still holds after its faces were listed again (an
/// erosion; the same nodes): every face of `surface`, placed at `node_position` (the nodes'
/// positions when the zone was found), lies in a cell that `cells` (the zone's, sealed) marks.
/// A particle within the reach of such a face now was within the reach plus twice the
/// displacement since of that place, so it is in the zone, as for the faces the zone was found
/// with (the caller's test of the displacement covers both); faces gone from the list only
/// leave the zone larger.
template <int D>
bool faces_in_marked_cells(const parts::ContactSurface<D>& surface,
                           const std::vector<Vec<D>>& node_position, const ZoneCells<D>& cells);

}  // namespace crater::contact
