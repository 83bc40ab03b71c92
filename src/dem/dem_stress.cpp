// The DEM part's output fields and the grains' Love-Weber stress (dem_part_impl.hpp,
// laws/grain_stress.hpp), computed in the force stages of frames only (Part::expect_frame).
//
// What a grain's stress sums: its contacts with other grains (contact law and parallel bond,
// the force of both at the pair's contact point, mid-way through the overlap), with the rigid
// walls and the fixed bodies of settling (at the wall point), and the absorbing walls' forces
// (held reaction and dashpots, at the wall point). Not summed: the contacts with other parts
// (src/contact/ hands back one force per grain, not its contact points), couples (rolling
// resistance, bond moments), gravity and local damping (at the centre: no moment).
#include <algorithm>

#include "dem/dem_part_impl.hpp"

namespace crater::dem::detail {

template <int D>
std::vector<fields::FieldView> DemPart<D>::point_fields() const {
  std::vector<fields::FieldView> out = f_.views(fields::kOutput);
  // A frame whose force stage was not announced (a failure frame) goes without the stress.
  if (!stress_current_)
    std::erase_if(out, [](const fields::FieldView& v) { return v.info->name == kStressField; });
  return out;
}

// grain_stresses, after the passes of a frame's force stage: per grain, the moments of its
// walls (left in stress_ by grain_pass), then of its owned pairs in list order, then of the
// pairs it receives in pair order, over its share of the bulk. The pairs' forces are the
// cache's (compute_forces keeps it written on a frame's stage) and their geometry the one
// pair_pass computed (the same positions, the same arithmetic): the same bits on any thread count.
template <int D>
void DemPart<D>::grain_stresses() {
  const bool bonds = !cache_.bond_f1.empty();
  // The force of pair k on its body 1 (its grain of lower id): contact and bond.
  auto force_on_1 = [&](std::size_t k) {
    Vec<D> f = Vec<D>::Zero();
    const std::uint8_t flags = cache_.flags[k];
    if (flags & kContactOn) f += cache_.contact[k].f1;
    if (bonds && (flags & kBondOn)) f += cache_.bond_f1[k];
    return f;
  };
  parallel::for_each(f_.size(), [&](Index i) {
    const auto at = static_cast<std::size_t>(i);
    SymTensor moment = stress_[i];
    for (auto k = static_cast<std::size_t>(pair_begin_[at]);
         k < static_cast<std::size_t>(pair_begin_[at + 1]); ++k) {
      if (cache_.flags[k] == 0) continue;
      const Index j = pair_j_[k];
      const ContactGeometry<D> g = sphere_sphere_geometry<D>(x_[i], r_[i], x_[j], r_[j]);
      moment += contact_moment<D>(Vec<D>(-g.arm1 * g.normal), force_on_1(k));
    }
    for (auto e = static_cast<std::size_t>(recv_begin_[at]);
         e < static_cast<std::size_t>(recv_begin_[at + 1]); ++e) {
      const auto k = static_cast<std::size_t>(recv_pair_[e]);
      if (cache_.flags[k] == 0) continue;
      const Index owner = pair_owner(k);
      const ContactGeometry<D> g = sphere_sphere_geometry<D>(x_[owner], r_[owner], x_[i], r_[i]);
      moment += contact_moment<D>(Vec<D>(g.arm2 * g.normal), Vec<D>(-force_on_1(k)));
    }
    stress_[i] = grain_stress(moment, grain_volume<D>(r_[i]), solid_fraction_);
  });
}

template std::vector<fields::FieldView> DemPart<2>::point_fields() const;
template std::vector<fields::FieldView> DemPart<3>::point_fields() const;
template void DemPart<2>::grain_stresses();
template void DemPart<3>::grain_stresses();

}  // namespace crater::dem::detail
