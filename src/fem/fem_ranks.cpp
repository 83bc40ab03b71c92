// The FEM part on several ranks (issue 29, docs/distributed.md, "The FEM part on ranks").
//
// The mesh is cut before the first step, when every rank has built it whole: the elements
// by a recursive coordinate bisection of their centres at rest (each weighing one), a node goes
// with its lowest-numbered element. A rank keeps its own elements and every element of its own
// nodes (ghost elements, whose state it computes alike from the same nodes), and the nodes of
// those elements (ghost nodes: another rank's), numbered as on one rank but for the gaps, so
// that every loop runs in the same order over what it keeps. A node's force is then gathered
// from all of its elements, here, in element order: the same bits as on one rank, with no sum
// across ranks. After every drift the owners send their ghost nodes' positions and velocities
// (the only exchange of a step); ghosts are never summed nor reported, and what the stages
// leave in them between drifts is never read. The books are kept per entity and summed over
// the own ones by the reproducible sum (fem_part.cpp), so they too have the same bits on any
// rank count. The cuts are made again as elements erode (rebalance): erosion thins a rank's
// load where the plate breaks, and the entities then move to their new ranks with all they hold.
#include <algorithm>
#include <array>
#include <cstring>
#include <numeric>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "fem/fem_part_impl.hpp"
#include "fields/spread.hpp"
#include "parallel/rcb.hpp"

namespace crater::fem::detail {
namespace {

/// The entries `keep` (ascending indices) of v.
template <class T>
std::vector<T> selected(const std::vector<T>& v, const std::vector<Index>& keep) {
  std::vector<T> out;
  out.reserve(keep.size());
  for (const Index i : keep)
    out.push_back(v[at(i)]);
  return out;
}

/// Keeps the entries `keep` of v; an empty vector stays empty.
template <class T>
void keep_entries(std::vector<T>& v, const std::vector<Index>& keep) {
  if (!v.empty()) v = selected(v, keep);
}

/// The lowest non-negative number over the ranks, or -1. Collective.
Index lowest_over_ranks(const parallel::Comm& comm, Index mine) {
  const parallel::Comm::ValueId best = comm.min_with_id({mine >= 0 ? Real(0) : Real(1), mine});
  return best.value == 0 ? best.id : -1;
}

/// The most entities a rank owns over the mean, from every entity's owner (1 for none).
Real most_over_mean(const std::vector<int>& owner, int ranks) {
  if (owner.empty()) return 1;
  std::vector<Index> per_rank(static_cast<std::size_t>(ranks), 0);
  for (const int r : owner)
    ++per_rank[static_cast<std::size_t>(r)];
  const Index most = *std::max_element(per_rank.begin(), per_rank.end());
  return static_cast<Real>(most) * ranks / static_cast<Real>(owner.size());
}

}  // namespace

// An element's centre at rest in the whole mesh: what the cuts bisect.
template <int D>
Vec<D> FemPart<D>::rest_centre(Index whole_element) const {
  Vec<D> c = Vec<D>::Zero();
  for (const Index n : whole_mesh_.elements[at(whole_element)])
    c += whole_mesh_.reference_position[at(n)] / Real(kElementNodes<D>);
  return c;
}

template <int D>
void FemPart<D>::distribute(const parallel::Comm& comm) {
  if (comm_) throw std::logic_error("fem: distribute() twice");
  const Index ne = mesh_.element_count();
  // The mesh as it is before the cut, kept on every rank: the contacts' surface of the whole
  // mesh, and what the cuts made again select from (with the loads and groups in its numbering).
  whole_mesh_ = mesh_;
  whole_loads_ = loads_;
  whole_group_nodes_ = group_nodes_;
  whole_nodes_ = mesh_.node_count();
  whole_elements_ = ne;
  if (comm.root()) whole_elements_nodes_ = mesh_.elements;
  // The elements' owners: a bisection of their centres at rest (the same on every rank).
  std::vector<Vec<D>> centre(at(ne));
  for (Index e = 0; e < ne; ++e)
    centre[at(e)] = rest_centre(e);
  const std::vector<Real> weight(at(ne), 1);
  std::vector<int> element_owner =
      parallel::rcb<D>(std::span<const Vec<D>>(centre), std::span<const Real>(weight), comm.size())
          .owner;
  load_ratio_ = most_over_mean(element_owner, comm.size());
  comm_ = &comm;
  adopt_cuts(std::move(element_owner), /*moving=*/false);
}

// The cuts made again as elements erode (docs/distributed.md, "The FEM part on ranks"): every
// kTimeWindowSteps steps, the ranks' loads over the last window (by measured time, or by their
// live elements' count, domain.balance) decide through fields::rebalanced_cuts, each element
// weighing 1 while it lives and 0 once eroded; new cuts bisect the centres at rest so weighted,
// and the entities go to their new ranks with all they hold (adopt_cuts). Between steps only,
// and not while a coarser step's lagged positions or kept contact forces are pending
// (multi-rate stepping). Collective; every rank decides alike.
template <int D>
void FemPart<D>::rebalance() {
  if (lagged_.active || next_contact_.pending) return;
  // Only at the end of a window (its steps are every rank's): no pass over the elements else.
  if (busy_.by_time ? busy_.steps < fields::kTimeWindowSteps
                    : ++count_window_ < fields::kTimeWindowSteps)
    return;
  count_window_ = 0;
  std::vector<Vec<D>> x;
  std::vector<Real> w;
  for (Index e = 0; e < mesh_.element_count(); ++e) {
    if (ghost_element(e)) continue;
    x.push_back(rest_centre(element_id_[at(e)]));
    w.push_back(mesh_.eroded[at(e)] ? Real(0) : Real(1));
  }
  std::optional<parallel::RcbTree<D>> cuts =
      fields::rebalanced_cuts<D>(*comm_, std::span<const Vec<D>>(x), std::span<const Real>(w),
                                 &load_ratio_, &busy_, cuts_ ? &*cuts_ : nullptr);
  if (!cuts) return;
  std::vector<int> element_owner(at(whole_elements_));
  for (Index e = 0; e < whole_elements_; ++e)
    element_owner[at(e)] = cuts->owner(rest_centre(e));
  cuts_ = std::move(cuts);
  ++rebalances_;
  adopt_cuts(std::move(element_owner), /*moving=*/true);
}

// The ranks that keep each element and node under the elements' owners (the whole mesh's
// numbering): an element's owner and its nodes' owners keep it; a node's owner (that of its
// lowest-numbered element; the root's for a node of no element) and those of its elements keep
// the node.
template <int D>
struct Keepers {
  const ExplicitMesh<D>& whole;
  const std::vector<int>& element_owner;
  std::vector<int> node_owner;

  Keepers(const ExplicitMesh<D>& mesh, const std::vector<int>& owner)
      : whole(mesh), element_owner(owner), node_owner(mesh.node_entry_offsets.size() - 1, 0) {
    for (std::size_t i = 0; i + 1 < whole.node_entry_offsets.size(); ++i) {
      const Index first = whole.node_entry_offsets[i];
      if (first < whole.node_entry_offsets[i + 1])
        node_owner[i] = element_owner[at(whole.node_entries[at(first)] / kElementNodes<D>)];
    }
  }
  template <class Add>
  void element(Index e, Add&& add) const {
    add(element_owner[at(e)]);
    for (const Index n : whole.elements[at(e)])
      add(node_owner[at(n)]);
  }
  /// Those of node i's elements (not the node's owner).
  template <class Add>
  void elements_of_node(Index i, Add&& add) const {
    for (Index k = whole.node_entry_offsets[at(i)]; k < whole.node_entry_offsets[at(i) + 1]; ++k)
      element(whole.node_entries[at(k)] / kElementNodes<D>, add);
  }
};

// This rank's share under the elements' owners `element_owner` (the whole mesh's numbering,
// Keepers): its own elements and every element of its own nodes (ghost elements), and the nodes
// of those (ghost nodes: another rank's), numbered as on one rank but for the gaps. At the first
// cut (`moving` false) every rank holds the whole part and keeps its share; at a cut made again
// the entities come from their owners before (move_entities). The mesh's reference geometry,
// connectivity, loads and groups are taken from the whole mesh's.
template <int D>
void FemPart<D>::adopt_cuts(std::vector<int> element_owner, bool moving) {
  const Keepers<D> keep(whole_mesh_, element_owner);
  const Index ne = whole_elements_, nn = whole_nodes_;
  const int me = comm_->rank(), ranks = comm_->size();
  std::vector<Index> elements, nodes;  // kept here, ascending
  std::vector<std::uint8_t> of_kept(at(nn), 0);
  for (Index e = 0; e < ne; ++e) {
    bool kept = false;
    keep.element(e, [&](int r) { kept = kept || r == me; });
    if (!kept) continue;
    elements.push_back(e);
    for (const Index n : whole_mesh_.elements[at(e)])
      of_kept[at(n)] = 1;
  }
  for (Index i = 0; i < nn; ++i)
    if (of_kept[at(i)] || keep.node_owner[at(i)] == me) nodes.push_back(i);
  std::vector<Index> local_node(at(nn), -1), local_element(at(ne), -1);
  for (std::size_t k = 0; k < nodes.size(); ++k)
    local_node[at(nodes[k])] = static_cast<Index>(k);
  for (std::size_t k = 0; k < elements.size(); ++k)
    local_element[at(elements[k])] = static_cast<Index>(k);
  if (moving) {
    move_entities(keep, nodes, elements);
  } else {
    for_each_carried_vector([&](auto& v, MeshEntity entity) {
      keep_entries(v, entity == MeshEntity::node ? nodes : elements);
    });
  }
  take_whole_setup(nodes, elements, local_node, local_element);

  // Each own node goes to every other rank that keeps one of its elements; each ghost node
  // comes from its owner. Both lists ascend in the global numbers, so they pair up.
  send_nodes_.assign(at(ranks), {});
  receive_nodes_.assign(at(ranks), {});
  std::vector<std::uint8_t> to(at(ranks));
  for (const Index i : nodes) {
    const int owner = keep.node_owner[at(i)];
    if (owner != me) {
      receive_nodes_[at(owner)].push_back(local_node[at(i)]);
      continue;
    }
    std::fill(to.begin(), to.end(), 0);
    keep.elements_of_node(i, [&](int r) { to[at(r)] = 1; });
    for (int r = 0; r < ranks; ++r)
      if (r != me && to[at(r)]) send_nodes_[at(r)].push_back(local_node[at(i)]);
  }
  ghost_node_.resize(nodes.size());
  for (std::size_t k = 0; k < nodes.size(); ++k)
    ghost_node_[k] = keep.node_owner[at(nodes[k])] != me ? 1 : 0;
  ghost_element_.resize(elements.size());
  for (std::size_t k = 0; k < elements.size(); ++k)
    ghost_element_[k] = element_owner[at(elements[k])] != me ? 1 : 0;
  node_id_ = std::move(nodes);
  element_id_ = std::move(elements);
  node_owner_ = keep.node_owner;
  element_owner_ = std::move(element_owner);
  // The surface of the kept elements (the contacts see the whole mesh's instead): listed again,
  // it is not an erosion the whole surface must follow.
  const bool synced = surface_revision_ == synced_revision_;
  rebuild_surface();
  if (moving && synced) synced_revision_ = surface_revision_;
  node_layout_ = parts::WholeLayout{};
  build_node_layout(*comm_);
}

// At a cut made again: each own entity goes, in ascending numbers, to every rank that keeps it
// now, with every vector it carries (for_each_carried_vector); each entity kept here now comes
// from its owner before, read in the same order, vector after vector: one all-to-all.
template <int D>
void FemPart<D>::move_entities(const Keepers<D>& keep, const std::vector<Index>& nodes,
                               const std::vector<Index>& elements) {
  const int ranks = comm_->size();
  auto ranks_of = [](auto&& keepers) {
    std::vector<int> to;
    keepers([&](int r) { to.push_back(r); });
    std::sort(to.begin(), to.end());
    to.erase(std::unique(to.begin(), to.end()), to.end());
    return to;
  };
  std::vector<std::vector<int>> to_node(node_id_.size()), to_element(element_id_.size());
  for (std::size_t k = 0; k < node_id_.size(); ++k)
    if (!ghost_node(static_cast<Index>(k)))
      to_node[k] = ranks_of([&](auto&& add) {
        add(keep.node_owner[at(node_id_[k])]);
        keep.elements_of_node(node_id_[k], add);
      });
  for (std::size_t k = 0; k < element_id_.size(); ++k)
    if (!ghost_element(static_cast<Index>(k)))
      to_element[k] = ranks_of([&](auto&& add) { keep.element(element_id_[k], add); });
  std::vector<std::vector<std::byte>> send(at(ranks));
  for_each_carried_vector([&](auto& v, MeshEntity entity) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    const auto& to = entity == MeshEntity::node ? to_node : to_element;
    for (std::size_t k = 0; k < to.size(); ++k)
      for (const int r : to[k]) {
        auto& out = send[at(r)];
        const std::size_t b = out.size();
        out.resize(b + sizeof(T));
        std::memcpy(out.data() + b, &v[k], sizeof(T));
      }
  });
  const std::vector<std::vector<std::byte>> got = comm_->all_to_all(send);
  std::vector<std::size_t> read(at(ranks), 0);
  for_each_carried_vector([&](auto& v, MeshEntity entity) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    const bool of_nodes = entity == MeshEntity::node;
    const std::vector<Index>& kept = of_nodes ? nodes : elements;
    const std::vector<int>& owner_before = of_nodes ? node_owner_ : element_owner_;
    std::vector<T> moved(kept.size());
    for (std::size_t k = 0; k < kept.size(); ++k) {
      const auto r = at(owner_before[at(kept[k])]);
      if (read[r] + sizeof(T) > got[r].size())
        throw std::logic_error("fem: rank " + std::to_string(r) +
                               " sent fewer entities than it owned of those kept here");
      std::memcpy(static_cast<void*>(&moved[k]), got[r].data() + read[r], sizeof(T));
      read[r] += sizeof(T);
    }
    v = std::move(moved);
  });
  for (int r = 0; r < ranks; ++r)
    if (read[at(r)] != got[at(r)].size())
      throw std::logic_error("fem: rank " + std::to_string(r) + " sent entities not kept here");
}

// What a rank's share takes from the whole mesh every rank keeps (whole_mesh_, whole_loads_,
// whole_group_nodes_): the reference geometry, the connectivity in the local numbering and the
// node adjacency, the pressure loads' faces of its elements (in their order), the groups' nodes.
template <int D>
void FemPart<D>::take_whole_setup(const std::vector<Index>& nodes,
                                  const std::vector<Index>& elements,
                                  const std::vector<Index>& local_node,
                                  const std::vector<Index>& local_element) {
  mesh_.reference_position = selected(whole_mesh_.reference_position, nodes);
  mesh_.reference_volume = selected(whole_mesh_.reference_volume, elements);
  mesh_.elements = selected(whole_mesh_.elements, elements);
  for (auto& element_nodes : mesh_.elements)
    for (Index& n : element_nodes)
      n = local_node[at(n)];
  build_node_adjacency(mesh_);
  loads_.clear();
  for (const PressureLoad& load : whole_loads_) {
    PressureLoad& kept = loads_.emplace_back(PressureLoad{load.time_s, load.pressure_pa, {}, {}});
    for (std::size_t f = 0; f < load.faces.size(); ++f) {
      const Index e = local_element[at(load.element[f])];
      if (e < 0) continue;
      auto face = load.faces[f];
      for (Index& n : face)
        n = local_node[at(n)];
      kept.faces.push_back(face);
      kept.element.push_back(e);
    }
  }
  group_nodes_.clear();
  for (const auto& [group, members] : whole_group_nodes_) {
    std::vector<Index>& kept = group_nodes_[group];
    for (const Index n : members)
      if (local_node[at(n)] >= 0) kept.push_back(local_node[at(n)]);
  }
}

// The nodes as the contacts see them (contact_layout): in their numbering, each sent by its
// owner. Collective.
template <int D>
void FemPart<D>::build_node_layout(const parallel::Comm& comm) {
  std::vector<std::int64_t> own_ids;
  for (std::size_t k = 0; k < node_id_.size(); ++k) {
    if (ghost_node_[k]) continue;
    node_layout_.owned.push_back(static_cast<Index>(k));
    own_ids.push_back(node_id_[k]);
  }
  std::vector<std::int64_t> id_bytes;
  const std::vector<std::byte> all_ids =
      comm.all_gather(std::as_bytes(std::span<const std::int64_t>(own_ids)), &id_bytes);
  for (std::size_t b = 0; b < all_ids.size(); b += sizeof(std::int64_t)) {
    std::int64_t n;
    std::memcpy(&n, all_ids.data() + b, sizeof n);
    node_layout_.slot_of_gathered.push_back(static_cast<Index>(n));
  }
  for (const std::int64_t b : id_bytes)
    node_layout_.owned_by_rank.push_back(
        static_cast<Index>(b / static_cast<std::int64_t>(sizeof(std::int64_t))));
  node_layout_.whole_count = whole_nodes_;
  node_layout_.whole_of_local.assign(node_id_.begin(), node_id_.end());
}

template <int D>
const parts::WholeLayout* FemPart<D>::contact_layout() const {
  return comm_ ? &node_layout_ : nullptr;
}

// The nodes the whole contact surface reads: its faces' nodes. In the step an element erodes
// anywhere (its owner's flag is sent to every rank) the faces are listed again, which reads the
// positions of their elements' nodes: every node of the mesh then, as the listing is rare.
template <int D>
const std::vector<Index>* FemPart<D>::whole_surface_nodes() const {
  if (!comm_) return nullptr;
  const bool changed_here = surface_revision_ != synced_revision_;
  if (comm_->max(changed_here ? Real(1) : Real(0)) > 0 || whole_revision_ == 0) {
    std::vector<std::int64_t> eroded_own;
    for (Index e = 0; e < mesh_.element_count(); ++e)
      if (!ghost_element(e) && mesh_.eroded[at(e)]) eroded_own.push_back(element_id_[at(e)]);
    for (const std::int64_t e :
         parallel::all_gather(*comm_, std::span<const std::int64_t>(eroded_own)))
      whole_mesh_.eroded[at(e)] = 1;
    synced_revision_ = surface_revision_;
    whole_relist_ = true;
    whole_surface_nodes_.resize(at(whole_mesh_.node_count()));
    std::iota(whole_surface_nodes_.begin(), whole_surface_nodes_.end(), Index{0});
  }
  return &whole_surface_nodes_;
}

// The contact surface of the whole mesh on every rank, as one rank has it: the faces that
// whole_surface_nodes found, in the order surface_faces lists them, oriented by the positions of
// their elements' nodes (`whole_x`), with the stiffness of rebuild_surface.
template <int D>
std::optional<parts::ContactSurface<D>> FemPart<D>::whole_contact_surface(
    const std::vector<Vec<D>>& whole_x) const {
  if (!comm_) return std::nullopt;
  if (whole_relist_) {
    whole_mesh_.position = whole_x;
    const SurfaceFaces<D> sf = surface_faces(whole_mesh_, whole_face_index_);
    whole_faces_ = sf.nodes;
    whole_face_element_ = sf.element;
    whole_face_stiffness_ = face_stiffness(sf, whole_mesh_);
    ++whole_revision_;
    whole_relist_ = false;
    // The faces' nodes, ascending, each once: by a flag per node.
    std::vector<char> on(at(whole_mesh_.node_count()), 0);
    for (const auto& face : whole_faces_)
      for (const Index n : face)
        on[at(n)] = 1;
    whole_surface_nodes_.clear();
    for (Index n = 0; n < whole_mesh_.node_count(); ++n)
      if (on[at(n)]) whole_surface_nodes_.push_back(n);
  }
  parts::ContactSurface<D> s;
  s.faces = &whole_faces_;
  s.face_element = &whole_face_element_;
  s.face_stiffness = &whole_face_stiffness_;
  s.revision = whole_revision_;
  return s;
}

// The owners' values of every ghost node (collective): `bytes` per node, pack(i, out) of an own
// node i that another rank holds, unpack(i, in) of a ghost node i.
template <int D>
template <class Pack, class Unpack>
void FemPart<D>::exchange_ghost_nodes(std::size_t bytes, Pack&& pack, Unpack&& unpack) const {
  const auto ranks = static_cast<std::size_t>(comm_->size());
  std::vector<std::vector<std::byte>> send(ranks);
  for (std::size_t r = 0; r < ranks; ++r) {
    send[r].resize(send_nodes_[r].size() * bytes);
    std::byte* out = send[r].data();
    for (const Index i : send_nodes_[r]) {
      pack(i, out);
      out += bytes;
    }
  }
  const std::vector<std::vector<std::byte>> got = comm_->all_to_all(send);
  for (std::size_t r = 0; r < ranks; ++r) {
    if (got[r].size() != receive_nodes_[r].size() * bytes)
      throw std::logic_error("fem: ghost nodes from rank " + std::to_string(r) +
                             " do not match the nodes it owns here");
    const std::byte* in = got[r].data();
    for (const Index i : receive_nodes_[r]) {
      unpack(i, in);
      in += bytes;
    }
  }
}

template <int D>
void FemPart<D>::refresh_ghosts() {
  constexpr std::size_t kVec = sizeof(Vec<D>);
  exchange_ghost_nodes(
      2 * kVec,
      [&](Index i, std::byte* out) {
        std::memcpy(out, mesh_.position[at(i)].data(), kVec);
        std::memcpy(out + kVec, mesh_.velocity[at(i)].data(), kVec);
      },
      [&](Index i, const std::byte* in) {
        std::memcpy(static_cast<void*>(mesh_.position[at(i)].data()), in, kVec);
        std::memcpy(static_cast<void*>(mesh_.velocity[at(i)].data()), in + kVec, kVec);
      });
}

// A frame on ranks: the own nodes' positions and point fields, the own elements' cell fields,
// ordered by their global numbers on the root, with the whole mesh's cells: the file one rank
// writes, byte for byte.
template <int D>
std::optional<parts::GatheredPoints<D>> FemPart<D>::gathered_points() const {
  if (!comm_) return std::nullopt;
  parts::GatheredPoints<D> g = parts::gather_points<D>(
      *comm_, std::span<const std::int64_t>(node_id_), std::span<const Vec<D>>(mesh_.position),
      point_fields(), [&](Index i) { return !ghost_node(i); });
  parts::GatheredFields cells =
      parts::gather_fields(*comm_, std::span<const std::int64_t>(element_id_), cell_fields(),
                           [&](Index e) { return !ghost_element(e); });
  if (!comm_->root()) return g;
  g.cell = std::move(cells);
  for (const auto& element_nodes : whole_elements_nodes_) {
    for (const Index n : element_nodes)
      g.connectivity.push_back(n);
    g.offsets.push_back(static_cast<std::int64_t>(g.connectivity.size()));
  }
  g.cell_types.assign(whole_elements_nodes_.size(),
                      D == 2 ? std::uint8_t{9} : std::uint8_t{12});  // QUAD, HEXAHEDRON
  return g;
}

// A frame's piece on ranks: the own elements with their cell fields, and the nodes they use in
// local order with their point fields, those another rank owns with its values (one exchange,
// as refresh_ghosts': what the stages leave in a ghost node is not its value); the global
// numbers node_id and element_id place the piece in the whole mesh.
template <int D>
std::optional<parts::GatheredPoints<D>> FemPart<D>::own_piece() const {
  if (!comm_) return std::nullopt;
  static const fields::FieldInfo kNodeId{"node_id", "", fields::kNone};
  static const fields::FieldInfo kElementId{"element_id", "", fields::kNone};
  const Index nn = mesh_.node_count();
  // The point fields copied, their ghost nodes' values then from the owners (one exchange).
  std::vector<fields::FieldView> views = point_fields();
  std::vector<std::vector<Real>> reals(views.size());
  std::vector<std::vector<std::int64_t>> integers(views.size());
  std::size_t bytes = 0;
  for (std::size_t k = 0; k < views.size(); ++k) {
    auto& v = views[k];
    const std::size_t n = at(nn) * static_cast<std::size_t>(v.components);
    if (v.is_integer) {
      integers[k].assign(v.integer_data, v.integer_data + n);
      v.integer_data = integers[k].data();
    } else {
      reals[k].assign(v.real_data, v.real_data + n);
      v.real_data = reals[k].data();
    }
    bytes += static_cast<std::size_t>(v.components) * sizeof(Real);
  }
  static_assert(sizeof(Real) == sizeof(std::int64_t));
  // Node i's values of field k, as bytes.
  auto entry = [&](std::size_t k, Index i) {
    const std::size_t first = at(i) * static_cast<std::size_t>(views[k].components);
    return views[k].is_integer ? reinterpret_cast<std::byte*>(integers[k].data() + first)
                               : reinterpret_cast<std::byte*>(reals[k].data() + first);
  };
  exchange_ghost_nodes(
      bytes,
      [&](Index i, std::byte* out) {
        for (std::size_t k = 0; k < views.size(); ++k) {
          const std::size_t b = static_cast<std::size_t>(views[k].components) * sizeof(Real);
          std::memcpy(out, entry(k, i), b);
          out += b;
        }
      },
      [&](Index i, const std::byte* in) {
        for (std::size_t k = 0; k < views.size(); ++k) {
          const std::size_t b = static_cast<std::size_t>(views[k].components) * sizeof(Real);
          std::memcpy(entry(k, i), in, b);
          in += b;
        }
      });
  views.push_back(fields::FieldView{&kNodeId, 1, true, nullptr, node_id_.data(), nn});
  std::vector<Index> elements, rows;
  std::vector<Index> row_of(at(nn), -1);
  for (Index e = 0; e < mesh_.element_count(); ++e) {
    if (ghost_element(e)) continue;
    elements.push_back(e);
    for (const Index n : mesh_.elements[at(e)])
      row_of[at(n)] = 0;
  }
  for (Index n = 0; n < nn; ++n)
    if (row_of[at(n)] == 0) {
      row_of[at(n)] = static_cast<Index>(rows.size());
      rows.push_back(n);
    }
  parts::GatheredPoints<D> g;
  for (const Index n : rows)
    g.points.push_back(mesh_.position[at(n)]);
  g.point = parts::select_fields(views, rows);
  std::vector<fields::FieldView> cells = cell_fields();
  cells.push_back(
      fields::FieldView{&kElementId, 1, true, nullptr, element_id_.data(), mesh_.element_count()});
  g.cell = parts::select_fields(cells, elements);
  for (const Index e : elements) {
    for (const Index n : mesh_.elements[at(e)])
      g.connectivity.push_back(row_of[at(n)]);
    g.offsets.push_back(static_cast<std::int64_t>(g.connectivity.size()));
  }
  g.cell_types.assign(elements.size(), D == 2 ? std::uint8_t{9} : std::uint8_t{12});
  return g;
}

template <int D>
std::optional<parts::OwnNumbers> FemPart<D>::own_numbers() const {
  if (!comm_) return std::nullopt;
  parts::OwnNumbers n;
  n.point = parts::own_numbers_of(std::span<const std::int64_t>(node_id_),
                                  [&](Index i) { return ghost_node(i); });
  n.cell = parts::own_numbers_of(std::span<const std::int64_t>(element_id_),
                                 [&](Index e) { return ghost_element(e); });
  return n;
}

// The nodes numbered `numbers` (as on one rank), from their owners, on every rank: each rank
// sends the positions of those it owns (node_id_ ascends: the local numbering keeps the global
// order), one small all-gather.
template <int D>
std::vector<Vec<D>> FemPart<D>::points_numbered(const std::vector<Index>& numbers) const {
  if (!comm_) return parts::Part<D>::points_numbered(numbers);
  struct Found {
    std::int64_t slot;  // into `numbers`
    std::array<Real, D> x;
  };
  std::vector<Found> mine;
  for (std::size_t k = 0; k < numbers.size(); ++k) {
    const auto it = std::lower_bound(node_id_.begin(), node_id_.end(), numbers[k]);
    if (it == node_id_.end() || *it != numbers[k]) continue;
    const auto i = static_cast<Index>(it - node_id_.begin());
    if (ghost_node(i)) continue;
    Found f{static_cast<std::int64_t>(k), {}};
    for (int d = 0; d < D; ++d)
      f.x[at(d)] = mesh_.position[at(i)][d];
    mine.push_back(f);
  }
  const std::vector<Found> all = parallel::all_gather(*comm_, std::span<const Found>(mine));
  if (all.size() != numbers.size())
    throw std::logic_error("fem: a numbered node is owned by no rank, or by several");
  std::vector<Vec<D>> out(numbers.size());
  for (const Found& f : all)
    for (int d = 0; d < D; ++d)
      out[at(f.slot)][d] = f.x[at(d)];
  return out;
}

// The elements each rank owns (fewest, most), of them those not eroded (fewest, most), the ghost
// nodes and elements it keeps (mean, most), the bytes of one step's exchange summed over the
// ranks, and how often the cuts were made again.
template <int D>
std::vector<parts::Diagnostic> FemPart<D>::rank_figures() const {
  if (!comm_) return {};
  const parallel::Comm& comm = *comm_;
  auto flagged = [](const std::vector<std::uint8_t>& flags) {
    return static_cast<std::int64_t>(std::count(flags.begin(), flags.end(), 1));
  };
  const auto owned = static_cast<Real>(mesh_.element_count() - flagged(ghost_element_));
  Real live = 0;  // own elements not eroded
  for (Index e = 0; e < mesh_.element_count(); ++e)
    if (!ghost_element(e) && !mesh_.eroded[at(e)]) ++live;
  const std::int64_t ghosts = flagged(ghost_node_);
  const auto all_ghosts = static_cast<Real>(comm.sum(ghosts));
  const auto ranks = static_cast<Real>(comm.size());
  return {{"owned_min", comm.min(owned)},
          {"owned_max", comm.max(owned)},
          {"live_min", comm.min(live)},
          {"live_max", comm.max(live)},
          {"ghost_nodes_mean", all_ghosts / ranks},
          {"ghost_nodes_max", comm.max(static_cast<Real>(ghosts))},
          {"ghost_elements_max", comm.max(static_cast<Real>(flagged(ghost_element_)))},
          {"ghost_refresh_bytes_per_step", all_ghosts * 2 * sizeof(Vec<D>)},
          {"load_ratio", load_ratio_},
          {"rebalances", static_cast<Real>(rebalances_)}};
}

// A checkpoint on ranks: every vector gathered on the root from the entities' owners and
// written whole, then the values the ranks agree on: the file one rank writes, byte for byte,
// which resumes there or on any rank count (each rank loads it whole, then distribute()).
template <int D>
void FemPart<D>::save_gathered(parts::StateWriter& w) const {
  const parallel::Comm& comm = *comm_;
  ForceReport report;
  const parts::StableStep step = stable_step();
  report.stable_dt_s = step.dt_s;
  report.limiting_element = step.entity_id;
  report.inverted_element = lowest_over_ranks(comm, last_.inverted_element);
  report.first_mass_scaled_element = lowest_over_ranks(comm, last_.first_mass_scaled_element);
  const Index mass_scaled_first = lowest_over_ranks(comm, mass_scaled_first_);
  if (comm.root()) w.tag("fem");
  for_each_state_vector(*this, [&](const auto& v, MeshEntity entity, const char*) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    const bool of_nodes = entity == MeshEntity::node;
    const std::vector<Index>& id = of_nodes ? node_id_ : element_id_;
    constexpr std::size_t kRow = sizeof(std::int64_t) + sizeof(T);
    std::vector<std::byte> mine;
    for (std::size_t k = 0; k < v.size(); ++k) {
      if (of_nodes ? ghost_node(static_cast<Index>(k)) : ghost_element(static_cast<Index>(k)))
        continue;
      const std::size_t at_byte = mine.size();
      mine.resize(at_byte + kRow);
      std::memcpy(mine.data() + at_byte, &id[k], sizeof(std::int64_t));
      std::memcpy(mine.data() + at_byte + sizeof(std::int64_t), &v[k], sizeof(T));
    }
    const std::vector<std::byte> all = comm.gather(mine);
    if (!comm.root()) return;
    std::vector<T> whole(at(of_nodes ? whole_nodes_ : whole_elements_));
    if (all.size() != whole.size() * kRow)
      throw std::logic_error("fem: a checkpoint gathered from the ranks misses entities");
    for (std::size_t q = 0; q < whole.size(); ++q) {
      std::int64_t k;
      std::memcpy(&k, all.data() + q * kRow, sizeof k);
      std::memcpy(static_cast<void*>(&whole[at(k)]), all.data() + q * kRow + sizeof(std::int64_t),
                  sizeof(T));
    }
    w.vector(whole);
  });
  if (comm.root()) archive_values(w, *this, report, mass_scaled_first);
}

#define CRATER_FEM_RANKS(D)                                                                  \
  template const parts::WholeLayout* FemPart<D>::contact_layout() const;                     \
  template const std::vector<Index>* FemPart<D>::whole_surface_nodes() const;                \
  template std::optional<parts::ContactSurface<D>> FemPart<D>::whole_contact_surface(        \
      const std::vector<Vec<D>>&) const;                                                     \
  template void FemPart<D>::distribute(const parallel::Comm&);                               \
  template void FemPart<D>::rebalance();                                                     \
  template void FemPart<D>::refresh_ghosts();                                                \
  template std::optional<parts::GatheredPoints<D>> FemPart<D>::gathered_points() const;      \
  template std::optional<parts::GatheredPoints<D>> FemPart<D>::own_piece() const;            \
  template std::optional<parts::OwnNumbers> FemPart<D>::own_numbers() const;                 \
  template std::vector<parts::Diagnostic> FemPart<D>::rank_figures() const;                  \
  template std::vector<Vec<D>> FemPart<D>::points_numbered(const std::vector<Index>&) const; \
  template void FemPart<D>::save_gathered(parts::StateWriter&) const;
CRATER_FEM_RANKS(2)
CRATER_FEM_RANKS(3)
#undef CRATER_FEM_RANKS

}  // namespace crater::fem::detail
