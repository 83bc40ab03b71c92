// The contact forces handed to a DEM part where they touch (DemPart::add_touched_contact_forces,
// docs/performance.md "Contact forces handed over where they touch"): the same grains, energies
// and contact work, bit for bit, as the full hand-over (add_contact_forces), while the grains
// touched change from step to step and the bed re-sorts its grains in its arrays.
//
// The bed of bursting_bed.hpp bursts into the empty half of its box, so its neighbour lists
// are built again and its grains re-sorted many times. Every step each of two such beds takes
// a contact force and torque on a changing set of grains (chosen by id, a fifth of them, the
// set moving every 7 steps; a few of them given exactly zero), the reference through the full
// pass, the other through the touched ones.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "bursting_bed.hpp"
#include "dem/dem_part_impl.hpp"
#include "io/scenario/load.hpp"
#include "solver/assembly.hpp"

namespace crater::dem::detail {
namespace {

template <int D>
std::unique_ptr<DemPart<D>> make_bed() {
  const io::Config config =
      io::load_scenario_text(test::bursting_bed_scenario(D, "handover"), "handover.toml", {});
  return std::make_unique<DemPart<D>>(solver::dem_settings(config, config.parts.at(0)));
}

// Step s's contact forces on `bed` in its current order, and the grains they touch
// (ascending): a fifth of the grains by id, the set moving every 7 steps; one in 7 of those
// given exactly zero.
template <int D>
void contact_forces(const DemPart<D>& bed, int s, std::vector<Vec<D>>& f,
                    std::vector<AngularVec<D>>& t, std::vector<Index>& touched) {
  const std::vector<std::int64_t>& id = *bed.contact_points()->id;
  const Index n = bed.local_count();
  f.assign(at(n), Vec<D>::Zero());
  if constexpr (D == 2)
    t.assign(at(n), Real(0));
  else
    t.assign(at(n), Vec<3>::Zero());
  touched.clear();
  for (Index i = 0; i < n; ++i) {
    const std::int64_t k = id[at(i)];
    if ((k + s / 7) % 5 != 0) continue;
    touched.push_back(i);
    if (k % 7 == 0) continue;
    const Real a = 1e-3 * std::sin(0.37 * static_cast<Real>(k) + 0.11 * s);
    for (int d = 0; d < D; ++d)
      f[at(i)][d] = a * static_cast<Real>(d + 1);
    if constexpr (D == 2)
      t[at(i)] = 1e-6 * a;
    else
      t[at(i)] = Vec<3>(1e-6 * a, -2e-6 * a, 3e-6 * a);
  }
}

// Position, velocity and angular velocity of every grain, by id.
template <int D>
std::vector<Real> state_by_id(const DemPart<D>& bed) {
  const auto p = *bed.contact_points();
  const std::vector<Vec<D>>& x = *bed.geometry().points;
  constexpr int kWords = 2 * D + (D == 2 ? 1 : 3);
  std::vector<Real> out(at(bed.local_count()) * kWords);
  for (Index i = 0; i < bed.local_count(); ++i) {
    Real* g = out.data() + at((*p.id)[at(i)]) * kWords;
    for (int d = 0; d < D; ++d) {
      g[d] = x[at(i)][d];
      g[D + d] = (*p.velocity)[at(i)][d];
    }
    if constexpr (D == 2)
      g[2 * D] = (*p.angular_velocity)[at(i)];
    else
      for (int d = 0; d < 3; ++d)
        g[2 * D + d] = (*p.angular_velocity)[at(i)][d];
  }
  return out;
}

template <int D>
void touched_matches_full(int steps) {
  auto ref = make_bed<D>();
  auto bed = make_bed<D>();
  const Real dt = 0.5 * ref->stable_step().dt_s;
  const std::vector<std::int64_t> first_order = *bed->contact_points()->id;
  std::vector<Vec<D>> f;
  std::vector<AngularVec<D>> t;
  std::vector<Index> touched;
  int resorted = 0;  // steps whose order of grains differs from the last step's
  std::vector<std::int64_t> last_order = first_order;
  ref->compute_forces(0);
  bed->compute_forces(0);
  for (int s = 1; s <= steps; ++s) {
    for (DemPart<D>* p : {ref.get(), bed.get()}) {
      p->advance((s - 1) * dt, dt);
      p->compute_forces(s * dt);
      contact_forces<D>(*p, s, f, t, touched);
      if (p == ref.get())
        p->add_contact_forces(f, t);
      else
        p->add_touched_contact_forces(f, t, touched);
      p->finish_step(dt);
    }
    const std::vector<std::int64_t>& order = *bed->contact_points()->id;
    resorted += order != last_order;
    last_order = order;
    const std::vector<Real> a = state_by_id<D>(*ref), b = state_by_id<D>(*bed);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(Real)), 0) << "step " << s;
    const parts::Energies ea = ref->energies(), eb = bed->energies();
    ASSERT_EQ(ea.contact_j, eb.contact_j) << "step " << s;
    ASSERT_EQ(ea.kinetic_j, eb.kinetic_j) << "step " << s;
  }
  // The test tests something: the contacts did work, and the grains were re-sorted.
  EXPECT_NE(ref->energies().contact_j, 0.0);
  EXPECT_GE(resorted, 3);
}

TEST(DemContactHandover, TouchedGrainsAloneGiveTheFullPassBitForBit2D) {
  touched_matches_full<2>(400);
}

TEST(DemContactHandover, TouchedGrainsAloneGiveTheFullPassBitForBit3D) {
  touched_matches_full<3>(300);
}

}  // namespace
}  // namespace crater::dem::detail
