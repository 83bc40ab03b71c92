// The DEM part's parallel bonds (dem_part_impl.hpp), made at t = 0; the force stage updates and
// breaks them (dem_pair_loop.cpp: pair_law, close_bond_slots).
#include <fmt/format.h>
#include <algorithm>
#include <stdexcept>

#include "dem/dem_part_impl.hpp"

namespace crater::dem::detail {
namespace {

BondRadiusRule bond_rule(BondRadius r) {
  switch (r) {
    case BondRadius::Mean:
      return BondRadiusRule::MeanRadius;
    case BondRadius::Effective:
      return BondRadiusRule::EffectiveRadius;
    case BondRadius::Min:
      break;
  }
  return BondRadiusRule::MinRadius;
}

}  // namespace

// Parallel bonds at t = 0 between the grains whose surface gap is at most gap_fraction x the
// smaller radius, held by the lower id (both buffers, so the first step reads them).
template <int D>
void DemPart<D>::make_bonds() {
  const Index n = f_.size();
  bonded_ = true;
  bond_partner_.assign(static_cast<std::size_t>(n) * kMaxContacts, kNoContact);
  bond_.assign(static_cast<std::size_t>(n) * kMaxContacts, ParallelBondState<D>{});
  update_neighbors();
  const BondRadiusRule rule = bond_rule(cfg_.bonds.radius_rule);
  for (Index i = 0; i < n; ++i) {
    int k = 0;
    for (const Index j : list_.of(i)) {
      const Real gap = (x_[i] - x_[j]).norm() - r_[i] - r_[j];
      if (gap > cfg_.bonds.gap_fraction * std::min(r_[i], r_[j])) continue;
      ++bonds_[i];
      if (id_[i] > id_[j]) continue;
      if (k == kMaxContacts)
        throw std::runtime_error(
            fmt::format("part '{}': grain {} has more than {} bonds (grains placed overlapping?)",
                        name_, id_[i], kMaxContacts));
      const std::size_t at =
          static_cast<std::size_t>(i) * kMaxContacts + static_cast<std::size_t>(k++);
      bond_partner_[at] = id_[j];
      bond_[at] = parallel_bond_state<D>(
          parallel_bond_radius(rule, cfg_.bonds.radius_multiplier, r_[i], r_[j]));
      ++bonds_initial_;
    }
  }
  bond_partner_new_ = bond_partner_;
  bond_new_ = bond_;
}

template void DemPart<2>::make_bonds();
template void DemPart<3>::make_bonds();

}  // namespace crater::dem::detail
