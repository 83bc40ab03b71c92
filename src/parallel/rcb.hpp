// Recursive coordinate bisection (RCB): which rank owns each entity of a decomposition over all
// parts (issue 29, docs/distributed.md, "Decomposition, halos, migration").
//
// The entities of a set are cut across the longest side of their bounding box, at the point
// where the weight on the lower side first reaches its share: the set's weight times the ranks
// given to that side over the set's ranks (a set of r ranks gives floor(r / 2) to the lower
// side). Each side is cut again until one rank remains. An entity's weight is its cost (a
// part's cost model times its rank's measured time per unit of it, fields/balance.hpp), so that
// a rank's box holds about the same work, not the same count. Cuts made again keep the axes of
// the cuts before where the box allows (kKeepAxis).
//
// Along a cut, entities are ordered by the coordinate and then by their index, and the weights
// are summed in that order, so the owners depend only on the positions, weights and rank count:
// not on threads, and not on the order of the input beyond the index that breaks exact ties of
// a coordinate. The boxes are those of the owned entities; two ranks' boxes meet at most on the
// plane of their cut.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <span>
#include <stdexcept>
#include <vector>

#include "core/types.hpp"

namespace crater::parallel {

/// What RCB gives: each entity's rank, and each rank's weight and entity count.
struct Decomposition {
  std::vector<int> owner;    // per entity, in [0, ranks)
  std::vector<Real> weight;  // per rank
  std::vector<Index> count;  // per rank
};

/// The cuts of an RCB as a tree, which gives an owner to any point, not only to the entities
/// it was made from: a point below a node's cut (x[axis] < at) goes to its lower side. An
/// entity exactly on a cut may go to the other side than RCB gave it (RCB breaks such ties by
/// index); the tree is a function of the position alone, which is what a rank needs to send a
/// moving entity to its owner without a gather.
struct RcbNode {
  int axis = -1;  // -1: a leaf, owned by `rank`
  Real at = 0;
  int rank = 0;
  int lower = -1, upper = -1;  // children (nodes)
};
template <int D>
struct RcbTree {
  std::vector<RcbNode> nodes;  // nodes[0]: the root
  int owner(const Vec<D>& x) const {
    int k = 0;
    while (nodes[static_cast<std::size_t>(k)].axis >= 0) {
      const RcbNode& n = nodes[static_cast<std::size_t>(k)];
      k = x[n.axis] < n.at ? n.lower : n.upper;  // NaN: the upper side
    }
    return nodes[static_cast<std::size_t>(k)].rank;
  }
};

/// Cuts made again keep a node's axis of the cuts before (rcb_tree's `before`) while that side
/// of the box is at least this fraction of its longest: a bed as wide as it is long would
/// otherwise swap axes between two cuts for a grain thrown a little further one way, and send
/// half its entities to another rank instead of the few a moved cut sends.
inline constexpr Real kKeepAxis = 0.9;

namespace detail {

// Bisects entities ids[first, last) among ranks [rank0, rank0 + ranks); records its cuts in
// `tree` (if given) and returns the node it made there (-1 without a tree). `before`: the tree
// of the cuts made before (or null), whose node at the same place lends its axis (kKeepAxis).
template <int D>
int bisect(std::span<const Vec<D>> x, std::span<const Real> w, std::vector<Index>& ids,
           std::size_t first, std::size_t last, int rank0, int ranks, std::vector<int>& owner,
           std::vector<RcbNode>* tree = nullptr, const std::vector<RcbNode>* before = nullptr) {
  const int node = tree ? static_cast<int>(tree->size()) : -1;
  if (tree) tree->push_back(RcbNode{.rank = rank0});
  if (ranks == 1 || last - first <= 1) {
    for (std::size_t k = first; k < last; ++k)
      owner[static_cast<std::size_t>(ids[k])] = rank0;
    return node;
  }
  Vec<D> lo = Vec<D>::Constant(std::numeric_limits<Real>::infinity());
  Vec<D> hi = -lo;
  for (std::size_t k = first; k < last; ++k) {
    const auto i = static_cast<std::size_t>(ids[k]);
    lo = lo.cwiseMin(x[i]);
    hi = hi.cwiseMax(x[i]);
  }
  int axis = 0;  // the longest side; the lowest axis on ties
  for (int a = 1; a < D; ++a)
    if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
  if (before && node >= 0 && static_cast<std::size_t>(node) < before->size()) {
    const int kept = (*before)[static_cast<std::size_t>(node)].axis;
    if (kept >= 0 && kept < D && hi[kept] - lo[kept] >= kKeepAxis * (hi[axis] - lo[axis]))
      axis = kept;
  }
  const auto begin = ids.begin() + static_cast<std::ptrdiff_t>(first);
  const auto end = ids.begin() + static_cast<std::ptrdiff_t>(last);
  std::sort(begin, end, [&](Index a, Index b) {
    const Real xa = x[static_cast<std::size_t>(a)][axis], xb = x[static_cast<std::size_t>(b)][axis];
    return xa < xb || (xa == xb && a < b);
  });
  Real total = 0;  // in the sorted order: the same bits whatever order the set came in
  for (auto it = begin; it != end; ++it)
    total += w[static_cast<std::size_t>(*it)];
  const int lower_ranks = ranks / 2;
  const Real share = total * static_cast<Real>(lower_ranks) / static_cast<Real>(ranks);
  // The lower side takes entities until its weight reaches its share, and keeps the one that
  // crosses it when that leaves the two sides closer to their shares; each side keeps at least
  // one entity while there are enough.
  std::size_t cut = first;
  Real below = 0;
  while (cut < last) {
    const Real next = below + w[static_cast<std::size_t>(ids[cut])];
    if (next > share) {
      if (next - share < share - below) {
        below = next;
        ++cut;
      }
      break;
    }
    below = next;
    ++cut;
  }
  cut = std::clamp(cut, first + 1, last - 1);
  // The cut at the first upper entity's coordinate (entities sharing it go upper); read before
  // the sides are sorted again.
  const Real at = x[static_cast<std::size_t>(ids[cut])][axis];
  const int lower = bisect<D>(x, w, ids, first, cut, rank0, lower_ranks, owner, tree, before);
  const int upper = bisect<D>(x, w, ids, cut, last, rank0 + lower_ranks, ranks - lower_ranks, owner,
                              tree, before);
  if (tree) {
    RcbNode& n = (*tree)[static_cast<std::size_t>(node)];
    n.axis = axis;
    n.at = at;
    n.lower = lower;
    n.upper = upper;
  }
  return node;
}

}  // namespace detail

/// The owner of each entity (positions x, weights w >= 0, one each) among `ranks` ranks by
/// recursive coordinate bisection. With fewer entities than ranks, some ranks own none.
template <int D>
Decomposition rcb(std::span<const Vec<D>> x, std::span<const Real> w, int ranks) {
  if (ranks < 1) throw std::invalid_argument("rcb: the rank count must be at least 1");
  if (x.size() != w.size()) throw std::invalid_argument("rcb: one weight per entity is needed");
  for (const Real wi : w)
    if (!(wi >= 0) || !std::isfinite(wi))
      throw std::invalid_argument("rcb: weights must be finite and not negative");
  Decomposition d;
  d.owner.assign(x.size(), 0);
  std::vector<Index> ids(x.size());
  std::iota(ids.begin(), ids.end(), Index{0});
  detail::bisect<D>(x, w, ids, 0, ids.size(), 0, ranks, d.owner);
  d.weight.assign(static_cast<std::size_t>(ranks), 0);
  d.count.assign(static_cast<std::size_t>(ranks), 0);
  for (std::size_t i = 0; i < x.size(); ++i) {  // in entity order: the same sums every time
    d.weight[static_cast<std::size_t>(d.owner[i])] += w[i];
    ++d.count[static_cast<std::size_t>(d.owner[i])];
  }
  return d;
}

/// The tree of the cuts RCB makes for these entities (RcbTree). `before`: the cuts these
/// replace (the same rank count), whose axes are kept where the box allows (kKeepAxis).
template <int D>
RcbTree<D> rcb_tree(std::span<const Vec<D>> x, std::span<const Real> w, int ranks,
                    const RcbTree<D>* before = nullptr) {
  if (ranks < 1) throw std::invalid_argument("rcb: the rank count must be at least 1");
  if (x.size() != w.size()) throw std::invalid_argument("rcb: one weight per entity is needed");
  RcbTree<D> t;
  std::vector<int> owner(x.size(), 0);
  std::vector<Index> ids(x.size());
  std::iota(ids.begin(), ids.end(), Index{0});
  detail::bisect<D>(x, w, ids, 0, ids.size(), 0, ranks, owner, &t.nodes,
                    before ? &before->nodes : nullptr);
  return t;
}

}  // namespace crater::parallel
