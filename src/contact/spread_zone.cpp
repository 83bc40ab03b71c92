// The contact zones' views of contacts on ranks (spread_coupling.hpp, docs/distributed.md
// "Contacts on ranks"): a particle part's view holds only the particles that can touch the other
// side's bodies this step, in the whole part's order. Every pair in contact is then in the views,
// visited in the order of one rank, so the forces, diagnostics and history keep one rank's bits;
// what the step limits read of the whole part (its count, lightest mass, largest radius) travels
// beside the view.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <optional>

#include "contact/contact_zone.hpp"
#include "contact/face_search.hpp"
#include "contact/particle_particle.hpp"
#include "contact/spread_coupling.hpp"

namespace crater::contact {

namespace {

constexpr Real kInf = std::numeric_limits<Real>::infinity();

// A value's bytes appended to a record, or read from one.
template <class T>
void put(std::vector<std::byte>& out, const T& v) {
  const auto* b = reinterpret_cast<const std::byte*>(&v);
  out.insert(out.end(), b, b + sizeof(T));
}
template <class T>
void get(const std::byte*& in, T& v) {
  std::memcpy(static_cast<void*>(&v), in, sizeof(T));
  in += sizeof(T);
}

}  // namespace

template <int D>
void WholePart<D>::assemble_zone(const parallel::Comm& comm, const parts::Part<D>& part,
                                 const parts::WholeLayout& layout,
                                 const std::vector<std::pair<Index, int>>& to,
                                 Real largest_radius_m) {
  const auto local = part.contact_points();
  if (!local) throw std::logic_error("part '" + part.name() + "' has no contact points");
  is_points_ = true;
  zone_ = true;
  Points& p = points_;
  p.spins = local->angular_velocity != nullptr;
  p.offsets = local->surface_offset && local->surface_overlap;
  p.ids = local->id != nullptr;
  // What the step limits read of the whole part: each extreme is exact in any order.
  Real m_min = kInf;
  for (const Index i : layout.owned)
    m_min = std::min(m_min, (*local->mass)[at(i)]);
  whole_lightest_kg_ = comm.min(m_min);
  whole_largest_radius_m_ = largest_radius_m;
  whole_count_ = layout.whole_count;
  // One record per particle and rank it goes to: its place in the whole part, then its fields.
  std::vector<std::vector<std::byte>> send(at(comm.size()));
  for (const auto& [i, rank] : to) {
    std::vector<std::byte>& out = send[at(rank)];
    put(out, static_cast<std::int64_t>(layout.whole_of_local[at(i)]));
    put(out, (*local->position)[at(i)]);
    put(out, (*local->velocity)[at(i)]);
    put(out, (*local->mass)[at(i)]);
    put(out, (*local->radius)[at(i)]);
    if (p.spins) put(out, (*local->angular_velocity)[at(i)]);
    if (p.offsets) {
      put(out, (*local->surface_offset)[at(i)]);
      put(out, (*local->surface_overlap)[at(i)]);
    }
    if (p.ids) put(out, (*local->id)[at(i)]);
  }
  const std::size_t record = sizeof(std::int64_t) + 2 * sizeof(Vec<D>) + 2 * sizeof(Real) +
                             (p.spins ? sizeof(AxialVec<D>) : 0) +
                             (p.offsets ? 2 * sizeof(Real) : 0) +
                             (p.ids ? sizeof(std::int64_t) : 0);
  const std::vector<std::vector<std::byte>> got = comm.all_to_all(send);
  // Every record received, with whether it is this rank's own, in the whole part's order (a
  // particle comes once: from its owner).
  struct From {
    std::int64_t whole;
    const std::byte* at;
    bool own;
  };
  std::vector<From> all;
  for (std::size_t r = 0; r < got.size(); ++r) {
    if (got[r].size() % record != 0)
      throw std::logic_error("contact zone of part '" + part.name() + "': a torn record");
    for (std::size_t q = 0; q < got[r].size() / record; ++q) {
      From f{0, got[r].data() + q * record, static_cast<int>(r) == comm.rank()};
      std::memcpy(&f.whole, f.at, sizeof(std::int64_t));
      all.push_back(f);
    }
  }
  std::sort(all.begin(), all.end(), [](const From& x, const From& y) { return x.whole < y.whole; });
  const std::size_t n = all.size();
  p.position.resize(n);
  p.velocity.resize(n);
  p.mass.resize(n);
  p.radius.resize(n);
  p.own.resize(n);
  p.angular_velocity.resize(p.spins ? n : 0);
  p.surface_offset.resize(p.offsets ? n : 0);
  p.surface_overlap.resize(p.offsets ? n : 0);
  p.id.resize(p.ids ? n : 0);
  std::vector<std::int64_t> sorted(n);
  for (std::size_t q = 0; q < n; ++q) {
    const std::byte* in = all[q].at;
    get(in, sorted[q]);
    get(in, p.position[q]);
    get(in, p.velocity[q]);
    get(in, p.mass[q]);
    get(in, p.radius[q]);
    if (p.spins) get(in, p.angular_velocity[q]);
    if (p.offsets) {
      get(in, p.surface_offset[q]);
      get(in, p.surface_overlap[q]);
    }
    if (p.ids) get(in, p.id[q]);
    p.own[q] = all[q].own ? 1 : 0;
  }
  // Each local entity's place in the view (a ghost's: its owner's particle, when it came), or -1.
  std::vector<Index> view_of_whole(at(layout.whole_count), -1);
  view_whole_.resize(n);
  for (std::size_t q = 0; q < n; ++q) {
    view_of_whole[at(sorted[q])] = static_cast<Index>(q);
    view_whole_[q] = static_cast<Index>(sorted[q]);
  }
  view_of_local_.resize(layout.whole_of_local.size());
  in_view_.clear();
  for (std::size_t i = 0; i < view_of_local_.size(); ++i) {
    view_of_local_[i] = view_of_whole[at(layout.whole_of_local[i])];
    if (view_of_local_[i] >= 0) in_view_.push_back(static_cast<Index>(i));
  }
}

template <int D>
bool SpreadContacts<D>::zoned_view(const PartList<D>& parts, std::size_t k) const {
  if (!zones_allowed_ || !parts[k]->contact_points()) return false;
  bool any = false;
  for (const auto& [a, b] : sides_) {
    if (a != k && b != k) continue;
    const std::size_t q = a == k ? b : a;
    any = true;
    if (!parts[q]->contact_points()) continue;  // against a surface
    const Index mine = layout_[k]->whole_count, theirs = layout_[q]->whole_count;
    if (mine < theirs || (mine == theirs && k < q)) return false;
  }
  return any;
}

template <int D>
const std::vector<char>& SpreadContacts<D>::zone_of(const PartList<D>& parts, std::size_t k,
                                                    Real r_max) {
  const parts::WholeLayout& layout = *layout_[k];
  const auto pts = parts[k]->contact_points();
  Zone& z = zones_[k];
  // Each contact of the part: the other side and the reach it needs now.
  struct Need {
    std::size_t part;
    std::optional<parts::ContactSurface<D>> surface;
    FaceCentres<D> centres;
    Real reach;
  };
  std::vector<Need> need;
  for (const auto& [a, b] : sides_) {
    if (a != k && b != k) continue;
    Need n{.part = a == k ? b : a, .surface = std::nullopt, .centres = {}, .reach = 0};
    n.surface = whole_[n.part]->contact_surface();
    if (n.surface) {
      // A particle touching a face lies within its radius of the face, whose points lie
      // within the face's half size of its centre (the candidates' test, face_search.cpp).
      n.centres = face_centres(*n.surface);
      n.reach = r_max + n.centres.half_size;
    } else {
      n.reach =
          r_max + whole_largest_radius(comm_, *parts[n.part]->contact_points(), *layout_[n.part]);
    }
    need.push_back(std::move(n));
  }
  // How far any side has moved since the zone was found (+inf: renumbered, or not found).
  // `which`: the entities to look at (null: every one).
  auto moved = [](const std::vector<Vec<D>>& now, const std::vector<Vec<D>>& then,
                  const std::vector<Index>* which) {
    Real m = 0;
    const std::size_t n = which ? which->size() : now.size();
    for (std::size_t q = 0; q < n; ++q) {
      const std::size_t i = which ? at((*which)[q]) : q;
      const Real d = (now[i] - then[i]).norm();
      m = std::isfinite(d) ? std::max(m, d) : kInf;
    }
    return m;
  };
  Real since = kInf;
  if (z.valid && z.others.size() == need.size() && layout.whole_of_local == z.whole_of_local &&
      layout.owned == z.owned) {
    since = moved(*pts->position, z.x, &layout.owned);
    for (std::size_t c = 0; c < need.size() && std::isfinite(since); ++c) {
      typename Zone::Other& o = z.others[c];
      if (need[c].surface) {
        const auto& xn = *need[c].surface->node_position;
        if (need[c].surface->revision != o.revision && xn.size() == o.x.size() && o.cells &&
            faces_in_marked_cells(*need[c].surface, o.x, *o.cells))
          o.revision = need[c].surface->revision;
        if (need[c].surface->revision != o.revision || xn.size() != o.x.size()) {
          since = kInf;
          break;
        }
        since = std::max(since, moved(xn, o.x, nullptr));
        continue;
      }
      const parts::WholeLayout& theirs = *layout_[need[c].part];
      if (theirs.whole_of_local != o.whole_of_local || theirs.owned != o.owned) {
        since = kInf;
        break;
      }
      since = std::max(since,
                       moved(*parts[need[c].part]->contact_points()->position, o.x, &theirs.owned));
    }
  }
  // The same decision on every rank: the largest displacement of every rank's, and each
  // contact's reach, which every rank computed alike.
  const Real g = comm_.max(since);
  bool keep = std::isfinite(g);
  for (std::size_t c = 0; keep && c < need.size(); ++c)
    keep = (need[c].reach + 2 * g) * (1 + Real(1e-9)) <= z.others[c].reach;
  if (keep) return z.in;

  // Found afresh, for a quarter more than each reach.
  z.valid = true;
  z.in.assign(layout.whole_of_local.size(), 0);
  z.whole_of_local = layout.whole_of_local;
  z.owned = layout.owned;
  z.x = *pts->position;
  z.others.assign(need.size(), {});
  z.search.resize(need.size());
  auto mark = [&](const ZoneCells<D>& cells) {
    for (const Index i : layout.owned)
      if (!z.in[at(i)] && cells.near((*pts->position)[at(i)])) z.in[at(i)] = 1;
  };
  for (std::size_t c = 0; c < need.size(); ++c) {
    typename Zone::Other& o = z.others[c];
    o.reach = need[c].reach * (1 + kZoneMargin);
    ZoneCells<D> cells(o.reach);
    if (need[c].surface) {
      o.revision = need[c].surface->revision;
      o.x = *need[c].surface->node_position;
      for (const Vec<D>& centre : need[c].centres.centre)
        cells.occupy(centre);
      cells.seal(nullptr);  // every rank holds the whole surface
      o.cells = cells;
    } else {
      // The other part's particles are spread over the ranks: the cells of every rank's own.
      const auto other = parts[need[c].part]->contact_points();
      const parts::WholeLayout& theirs = *layout_[need[c].part];
      o.whole_of_local = theirs.whole_of_local;
      o.owned = theirs.owned;
      o.x = *other->position;
      for (const Index i : theirs.owned)
        cells.occupy((*other->position)[at(i)]);
      cells.seal(&comm_);
    }
    mark(cells);
  }
  return z.in;
}

template <int D>
const std::vector<int>& SpreadContacts<D>::owners_of(std::size_t k) {
  const parts::WholeLayout& layout = *layout_[k];
  Owners& o = owners_[k];
  if (o.rank.size() == at(layout.whole_count) && o.slot_of_gathered == layout.slot_of_gathered &&
      o.owned_by_rank == layout.owned_by_rank)
    return o.rank;
  o.slot_of_gathered = layout.slot_of_gathered;
  o.owned_by_rank = layout.owned_by_rank;
  o.rank.assign(at(layout.whole_count), -1);
  std::size_t g = 0;
  for (std::size_t r = 0; r < layout.owned_by_rank.size(); ++r)
    for (Index q = 0; q < layout.owned_by_rank[r]; ++q, ++g)
      o.rank[at(layout.slot_of_gathered[g])] = static_cast<int>(r);
  return o.rank;
}

template <int D>
void SpreadContacts<D>::touching_of(const PartList<D>& parts, std::size_t k,
                                    const std::vector<char>& in_zone, Real r_max) {
  const parts::WholeLayout& layout = *layout_[k];
  const auto pts = parts[k]->contact_points();
  Zone& z = zones_[k];
  z.to.clear();
  const int me = comm_.rank();
  // This rank's own particles of the zone, as a view of their own (what the searches read: the
  // positions, contact radii and ids, and the whole part's largest radius).
  std::vector<Index> local;
  for (const Index i : layout.owned)
    if (in_zone[at(i)]) local.push_back(i);
  std::vector<Vec<D>> x(local.size());
  std::vector<Real> r(local.size());
  std::vector<std::int64_t> id(pts->id ? local.size() : 0);
  for (std::size_t q = 0; q < local.size(); ++q) {
    const std::size_t i = at(local[q]);
    x[q] = (*pts->position)[i];
    r[q] = (*pts->radius)[i];
    if (pts->id) id[q] = (*pts->id)[i];
    // A non-finite position goes to the pairing, which meets it as on one rank.
    if (!x[q].allFinite()) z.to.emplace_back(local[q], me);
  }
  parts::ContactPoints<D> mine;
  mine.position = &x;
  mine.radius = &r;
  if (pts->id) mine.id = &id;
  mine.whole_count = layout.whole_count;
  mine.whole_largest_radius_m = r_max;
  std::size_t c = 0;  // the part's contacts, in the order of zone_of's
  for (std::size_t contact = 0; contact < sides_.size(); ++contact) {
    const auto [a, b] = sides_[contact];
    if (a != k && b != k) continue;
    CrossCandidates<D>& kept = z.search[c++];
    const std::size_t other = a == k ? b : a;
    const std::vector<int>& owner = owners_of(other);
    if (const auto whole = whole_[other]->contact_surface()) {
      // The faces the contact sees, as its pairing searches them: each particle's face of
      // largest overlap is the same, and so are the nodes its force goes to.
      const parts::ContactSurface<D> surf = filters_[contact][a == k ? 1 : 0]->view(*whole);
      for (const FaceHit<D>& h : particle_face_hits(mine, surf, &kept)) {
        const Index i = local[at(h.body)];
        z.to.emplace_back(i, me);
        for (const Index node : (*surf.faces)[at(h.face)])
          z.to.emplace_back(i, owner[at(node)]);
      }
      continue;
    }
    // Whole: every particle of the other part.
    const auto& view = static_cast<const WholePart<D>&>(*whole_[other]);
    const auto theirs = view.contact_points();
    if (a == k) {
      for (const auto& pp : ParticleParticle<D>::pairs(mine, *theirs, &kept)) {
        z.to.emplace_back(local[at(pp.a)], me);
        z.to.emplace_back(local[at(pp.a)], owner[at(view.whole_index(pp.b))]);
      }
    } else {
      for (const auto& pp : ParticleParticle<D>::pairs(*theirs, mine, &kept)) {
        z.to.emplace_back(local[at(pp.b)], me);
        z.to.emplace_back(local[at(pp.b)], owner[at(view.whole_index(pp.a))]);
      }
    }
  }
  std::sort(z.to.begin(), z.to.end());
  z.to.erase(std::unique(z.to.begin(), z.to.end()), z.to.end());
}

template <int D>
void SpreadContacts<D>::agree(std::vector<PairLimits>& limits, std::vector<Real>* extra) const {
  // Each rank's extra numbers, then its three searches per contact as (step, body, reason),
  // all-gathered, then taken in rank order as one search takes bodies.
  std::vector<std::byte> mine;
  const std::size_t n_extra = extra ? extra->size() : 0;
  for (std::size_t q = 0; q < n_extra; ++q)
    put(mine, (*extra)[q]);
  for (const PairLimits& l : limits)
    for (const StepSearch* s : {&l.pair, &l.points, &l.other}) {
      put(mine, s->best.dt_s);
      put(mine, static_cast<std::int64_t>(s->best.entity_id));
      put(mine, static_cast<std::int64_t>(s->best.reason.size()));
      const auto* b = reinterpret_cast<const std::byte*>(s->best.reason.data());
      mine.insert(mine.end(), b, b + s->best.reason.size());
    }
  const std::vector<std::byte> all = comm_.all_gather(mine);
  for (PairLimits& l : limits)
    for (StepSearch* s : {&l.pair, &l.points, &l.other})
      *s = StepSearch{};
  const std::byte* in = all.data();
  const std::byte* end = all.data() + all.size();
  if (extra) extra->clear();
  while (in < end) {
    for (std::size_t q = 0; q < n_extra; ++q) {
      Real x = 0;
      get(in, x);
      extra->push_back(x);
    }
    for (PairLimits& l : limits)
      for (StepSearch* s : {&l.pair, &l.points, &l.other}) {
        Real dt = 0;
        std::int64_t entity = -1, length = 0;
        get(in, dt);
        get(in, entity);
        get(in, length);
        const std::string reason(reinterpret_cast<const char*>(in), at(length));
        in += length;
        s->consider(dt, static_cast<Index>(entity), [&] { return reason; });
      }
  }
}

template void WholePart<2>::assemble_zone(const parallel::Comm&, const parts::Part<2>&,
                                          const parts::WholeLayout&,
                                          const std::vector<std::pair<Index, int>>&, Real);
template void WholePart<3>::assemble_zone(const parallel::Comm&, const parts::Part<3>&,
                                          const parts::WholeLayout&,
                                          const std::vector<std::pair<Index, int>>&, Real);
template bool SpreadContacts<2>::zoned_view(const PartList<2>&, std::size_t) const;
template bool SpreadContacts<3>::zoned_view(const PartList<3>&, std::size_t) const;
template const std::vector<char>& SpreadContacts<2>::zone_of(const PartList<2>&, std::size_t, Real);
template const std::vector<char>& SpreadContacts<3>::zone_of(const PartList<3>&, std::size_t, Real);
template void SpreadContacts<2>::touching_of(const PartList<2>&, std::size_t,
                                             const std::vector<char>&, Real);
template void SpreadContacts<3>::touching_of(const PartList<3>&, std::size_t,
                                             const std::vector<char>&, Real);
template const std::vector<int>& SpreadContacts<2>::owners_of(std::size_t);
template const std::vector<int>& SpreadContacts<3>::owners_of(std::size_t);
template void SpreadContacts<2>::agree(std::vector<PairLimits>&, std::vector<Real>*) const;
template void SpreadContacts<3>::agree(std::vector<PairLimits>&, std::vector<Real>*) const;

}  // namespace crater::contact
