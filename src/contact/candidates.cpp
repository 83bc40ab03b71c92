// Candidate lists kept between steps; see candidates.hpp.
#include "contact/candidates.hpp"

#include <cmath>
#include <limits>

#include "parallel/parallel.hpp"

namespace crater::contact {

template <int D>
Real CrossCandidates<D>::Side::moved(std::span<const Vec<D>> now, const Numbering& n) const {
  constexpr Real kInf = std::numeric_limits<Real>::infinity();
  if (!known || !n.known || now.size() != x.size() || n.revision != revision) return kInf;
  if (!n.ids.empty() && n.ids.size() != ids.size()) return kInf;
  const bool by_id = !n.ids.empty();
  // One pass: the largest squared displacement, or +inf for a renumbered or non-finite point
  // (which a new build then reports as the neighbour search does).
  const Real moved_sq = parallel::max_over(static_cast<Index>(now.size()), 0.0, [&](Index i) {
    const auto k = static_cast<std::size_t>(i);
    if (by_id && n.ids[k] != ids[k]) return kInf;
    const Real d2 = (now[k] - x[k]).squaredNorm();
    return std::isfinite(d2) ? d2 : kInf;
  });
  return std::sqrt(moved_sq);
}

template <int D>
void CrossCandidates<D>::Side::keep(std::span<const Vec<D>> now, const Numbering& n) {
  x.assign(now.begin(), now.end());
  ids.assign(n.ids.begin(), n.ids.end());
  revision = n.revision;
  known = n.known;
}

template <int D>
const neighbors::NeighborList& CrossCandidates<D>::find(std::span<const Vec<D>> a,
                                                        const Numbering& number_a,
                                                        std::span<const Vec<D>> b,
                                                        const Numbering& number_b, Real reach) {
  // A pair within `reach` now was within reach + (moved a) + (moved b) at the build; the
  // factor covers the rounding of that sum and of the search's own distances.
  if (radius_ > 0) {
    const Real moved = a_.moved(a, number_a) + b_.moved(b, number_b);
    if ((reach + moved) * (1 + Real(1e-9)) <= radius_) return list_;
  }
  const Real radius = reach * (1 + kMarginFraction);
  radius_ = 0;  // none, should the build throw
  neighbors::build_cross_list<D>(a, b, radius, list_);
  radius_ = radius;
  a_.keep(a, number_a);
  b_.keep(b, number_b);
  ++builds_;
  return list_;
}

template class CrossCandidates<2>;
template class CrossCandidates<3>;

}  // namespace crater::contact
