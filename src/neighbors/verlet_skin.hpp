// When to rebuild a neighbour list built with a margin (Verlet 1967): a list built for the
// radius (1 + skin) x need holds every pair within `need` until some point has moved half the
// margin. The owner re-sorts its entities and rebuilds when stale() says so, then calls
// built().
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "core/types.hpp"
#include "parallel/parallel.hpp"

namespace crater::neighbors {

template <int D>
class VerletSkin {
 public:
  explicit VerletSkin(Real skin_fraction) : skin_(skin_fraction) {}

  /// True when no list exists or a point of x has moved too far for `need` (the interaction
  /// radius the owner needs now).
  bool stale(std::span<const Vec<D>> x, Real need) const {
    if (!listed() || x.size() != built_.size()) return true;
    return stale_given(moved_sq(x), static_cast<Index>(x.size()), need);
  }

  /// The largest displacement of a point of x from positions() (x as many points).
  Real moved(std::span<const Vec<D>> x) const { return std::sqrt(moved_sq(x)); }

  /// stale() for `count` points whose largest squared displacement from positions() the owner
  /// measured already (the max of |x_i - positions()_i|^2 from 0, NaNs skipped as std::max
  /// skips them).
  bool stale_given(Real moved_sq, Index count, Real need) const {
    if (!listed() || static_cast<std::size_t>(count) != built_.size()) return true;
    return 2 * std::sqrt(moved_sq) + need > radius_;
  }

  /// Records a rebuild at positions x (after any re-sort) and returns the radius to build for.
  Real built(std::span<const Vec<D>> x, Real need) {
    built_.assign(x.begin(), x.end());
    radius_ = (1 + skin_) * need;
    listed_ = true;
    ++builds_;
    return radius_;
  }

  /// After the owner removed entities between rebuilds (keep[i] != 0: entity i stays; the
  /// survivors keep their order): the list's indices are void, so stale() is true until the next
  /// built(), but the survivors' positions of the build are kept, with the radius, because they
  /// still give the order the owner holds its entities in (cell_sort_order of a subset is the
  /// restriction of the whole set's): a rank's share of them, a checkpoint written on ranks.
  void compacted(std::span<const std::uint8_t> keep) {
    std::size_t k = 0;
    for (std::size_t i = 0; i < built_.size() && i < keep.size(); ++i)
      if (keep[i]) built_[k++] = built_[i];
    built_.resize(k);
    listed_ = false;
  }

  /// Forgets the last rebuild, after the owner removed entities (the lists' indices are void):
  /// stale() is true until the next built(), and a checkpoint of this state restores no list.
  void invalidate() {
    built_.clear();
    radius_ = 0;
    listed_ = false;
  }

  /// This state with other positions of the last rebuild (the whole set's, gathered from
  /// the ranks that each hold a share of it, for a checkpoint of one rank).
  VerletSkin with_positions(std::vector<Vec<D>> built) const {
    VerletSkin s = *this;
    s.built_ = std::move(built);
    return s;
  }

  /// The radius of the last build (0 before the first and after invalidate()).
  Real radius() const { return radius_; }
  /// A list stands for positions(): built, and neither invalidated nor compacted since.
  bool listed() const { return radius_ > 0 && listed_; }
  /// The positions of the last rebuild (a restored list is rebuilt from them).
  std::span<const Vec<D>> positions() const { return built_; }

  template <class Writer>
  void save(Writer& w) const {
    w.tag("verlet_skin");
    w.value(radius_);
    w.value(builds_);
    w.value(listed_);
    w.vector(built_);
  }
  template <class Reader>
  void load(Reader& r) {
    r.tag("verlet_skin");
    r.value(radius_);
    r.value(builds_);
    r.value(listed_);
    r.vector(built_);
  }
  Index builds() const { return builds_; }

 private:
  // The largest squared displacement (then one root where a length is wanted: the same number,
  // sqrt being monotonic and correctly rounded).
  Real moved_sq(std::span<const Vec<D>> x) const {
    return parallel::max_over(static_cast<Index>(x.size()), 0.0, [&](Index i) {
      return (x[static_cast<std::size_t>(i)] - built_[static_cast<std::size_t>(i)]).squaredNorm();
    });
  }

  Real skin_;
  Real radius_ = 0;
  bool listed_ = false;
  std::vector<Vec<D>> built_;
  Index builds_ = 0;
};

}  // namespace crater::neighbors
