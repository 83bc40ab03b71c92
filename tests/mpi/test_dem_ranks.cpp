// The DEM part on ranks (src/dem/dem_ranks.cpp, docs/distributed.md "The DEM part on ranks"),
// on however many ranks the launcher gives (ctest: 1 without a launcher, mpirun -np 1 to 4).
//
// A box of polydisperse grains, a touching lattice in its lower half agitated at 6 m/s per
// component (restitution 0.9): the block bursts into the empty half and the grains cross the
// cuts between ranks again and again, with friction, rolling resistance and gravity. Every rank
// first runs the whole bed alone, on one thread and without a communicator (the code path of a
// run without MPI), as the reference; then the ranks run it together, each with its share, on
// the threads the environment gives (ctest: 1, and 2 on 2 ranks). At every tenth of the run,
// every rank gathers all ranks' owned grains and checks them against the reference, bit for
// bit: each grain owned exactly once (count and ids), its position, velocity and angular
// velocity; and the part's energies and work books, summed over the ranks. The verdict is then
// the same on every rank.
//
// On more than one rank the test also checks that it tests something: grains changed ranks
// and ghosts were held.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "../unit/dem/bursting_bed.hpp"
#include "dem/dem_part_impl.hpp"
#include "io/scenario/load.hpp"
#include "parallel/comm.hpp"
#include "solver/assembly.hpp"

namespace crater::dem::detail {
namespace {

// Moving walls: the top wall starts a little above the bed and comes down at 0.5 m/s, the
// right one holds 20 kPa by its servo; the bursting grains load both from the first
// milliseconds.
template <int D>
std::vector<std::string> moving_walls() {
  const std::string top = D == 3 ? "0.06" : "0.12";
  return {"parts.bed.dem.wall_motion=[{face=\"top\",position_m=" + top +
          ",velocity_m_s=-0.5},{face=\"right\",stress_pa=2.0e4,max_speed_m_s=0.5}]"};
}

template <int D>
std::unique_ptr<DemPart<D>> make_bed(const std::vector<std::string>& overrides) {
  const io::Config config = io::load_scenario_text(test::bursting_bed_scenario(D, "dem-ranks"),
                                                   "dem-ranks.toml", overrides);
  return std::make_unique<DemPart<D>>(solver::dem_settings(config, config.parts.at(0)));
}

// A grain's state as the ranks exchange it: id, then position, velocity, angular velocity.
template <int D>
constexpr std::size_t kWords = 1 + 2 * D + (D == 2 ? 1 : 3);

template <int D>
std::vector<Real> owned_state(const DemPart<D>& part) {
  const auto p = *part.contact_points();
  const std::vector<Vec<D>>& x = *part.geometry().points;
  std::vector<Real> out;
  for (Index i = 0; i < part.local_count(); ++i) {
    if (part.ghost(i)) continue;
    Real id;
    const std::int64_t k = (*p.id)[at(i)];
    std::memcpy(&id, &k, sizeof id);
    out.push_back(id);
    for (int d = 0; d < D; ++d)
      out.push_back(x[at(i)][d]);
    for (int d = 0; d < D; ++d)
      out.push_back((*p.velocity)[at(i)][d]);
    if constexpr (D == 2)
      out.push_back((*p.angular_velocity)[at(i)]);
    else
      for (int d = 0; d < 3; ++d)
        out.push_back((*p.angular_velocity)[at(i)][d]);
  }
  return out;
}

// The part's energies and work books (history.csv's columns of the part).
std::vector<Real> energy_words(const parts::Energies& e) {
  return {e.kinetic_j, e.internal_j, e.external_work_j, e.damping_j, e.contact_j, e.eroded_j};
}

// Grain states ordered by id (ids stored as their bits in a Real).
template <int D>
std::vector<std::vector<Real>> by_id(const std::vector<Real>& flat) {
  std::vector<std::vector<Real>> g;
  for (std::size_t k = 0; k + kWords<D> <= flat.size(); k += kWords<D>)
    g.emplace_back(flat.begin() + static_cast<std::ptrdiff_t>(k),
                   flat.begin() + static_cast<std::ptrdiff_t>(k + kWords<D>));
  auto id = [](const std::vector<Real>& s) {
    std::int64_t k;
    std::memcpy(&k, s.data(), sizeof k);
    return k;
  };
  std::sort(g.begin(), g.end(), [&](const auto& a, const auto& b) { return id(a) < id(b); });
  return g;
}

// How many grains of the reference differ from the ranks' (or are missing or doubled), by bits.
template <int D>
Index mismatches(const std::vector<std::vector<Real>>& ref,
                 const std::vector<std::vector<Real>>& got) {
  Index bad = ref.size() > got.size() ? static_cast<Index>(ref.size() - got.size())
                                      : static_cast<Index>(got.size() - ref.size());
  for (std::size_t k = 0; k < std::min(ref.size(), got.size()); ++k)
    bad += std::memcmp(ref[k].data(), got[k].data(), kWords<D> * sizeof(Real)) != 0;
  return bad;
}

// `overrides`: scenario keys set on the bed (moving_walls). Its history columns (the moving
// walls' positions, speeds and loads) are compared at every check too; returns the
// reference's at each check.
template <int D>
std::vector<std::vector<Real>> ranks_match_one_rank(
    int steps, const std::vector<std::string>& overrides = {}) {
  const auto& comm = parallel::Comm::world();
  constexpr int kChecks = 10;
  auto ref = make_bed<D>(overrides);
  auto bed = make_bed<D>(overrides);
  EXPECT_EQ(ref->count(), bed->count());
  const Index grains = ref->count();
  const Real dt = 0.5 * ref->stable_step().dt_s;
  bed->distribute(comm);
  // The reference: the whole bed on this rank, without a communicator, on one thread (the
  // ranks run on the threads the environment gives: ctest runs 1 and 2).
  const int threads = parallel::max_threads();
  parallel::set_threads(1);
  std::vector<std::vector<std::vector<Real>>> expected;
  std::vector<std::vector<Real>> expected_energy, expected_history;
  ref->compute_forces(0);
  for (int s = 1; s <= steps; ++s) {
    ref->advance((s - 1) * dt, dt);
    ref->compute_forces(s * dt);
    ref->finish_step(dt);
    if (s % (steps / kChecks) == 0) {
      expected.push_back(by_id<D>(owned_state<D>(*ref)));
      expected_energy.push_back(energy_words(ref->energies()));
      expected_history.push_back(ref->history_values());
    }
  }
  parallel::set_threads(threads);
  // The ranks together.
  Index ghosts = 0, arrived = 0;  // arrived: grains owned here that were not the step before
  std::vector<std::uint8_t> here(static_cast<std::size_t>(grains), 0), now = here;
  bed->compute_forces(0);
  std::vector<Index> bad;
  int bad_energy = 0, bad_history = 0;
  for (int s = 1; s <= steps; ++s) {
    bed->advance((s - 1) * dt, dt);
    bed->compute_forces(s * dt);
    bed->finish_step(dt);
    const auto* ids = bed->contact_points()->id;
    std::fill(now.begin(), now.end(), std::uint8_t{0});
    for (Index i = 0; i < bed->local_count(); ++i) {
      if (bed->ghost(i)) {
        ++ghosts;
        continue;
      }
      const auto id = at((*ids)[at(i)]);
      now[id] = 1;
      arrived += s > 1 && !here[id];
    }
    here.swap(now);
    if (s % (steps / kChecks) == 0) {
      const auto mine = owned_state<D>(*bed);
      const auto all = by_id<D>(parallel::all_gather(comm, std::span<const Real>(mine)));
      const auto energy = energy_words(bed->energies());  // collective
      bad_energy += std::memcmp(energy.data(), expected_energy[bad.size()].data(),
                                energy.size() * sizeof(Real)) != 0;
      const std::vector<Real> history = bed->history_values();
      const std::vector<Real>& want = expected_history[bad.size()];
      bad_history += history.size() != want.size() ||
                     std::memcmp(history.data(), want.data(), want.size() * sizeof(Real)) != 0;
      bad.push_back(mismatches<D>(expected[bad.size()], all));
    }
  }
  EXPECT_EQ(bad_energy, 0) << "checks at which the energies or work books differ from one rank's";
  EXPECT_EQ(bad_history, 0) << "checks at which the history columns differ from one rank's";
  for (std::size_t c = 0; c < bad.size(); ++c)
    EXPECT_EQ(bad[c], 0) << "grains that differ from one rank's run at check " << c + 1 << " of "
                         << kChecks << " (" << comm.size() << " ranks, " << grains << " grains)";
  // Against a vacuous pass: on several ranks, grains changed hands, ghosts were held.
  const std::int64_t moves = comm.sum(static_cast<std::int64_t>(arrived));
  const std::int64_t held = comm.sum(static_cast<std::int64_t>(ghosts));
  if (comm.root())
    std::printf(
        "  %d ranks x %d threads, %lld grains, %d steps: %lld arrivals of a grain on a rank, %lld "
        "ghosts "
        "held (summed over the steps)\n",
        comm.size(), threads, static_cast<long long>(grains), steps, static_cast<long long>(moves),
        static_cast<long long>(held));
  if (comm.size() > 1) {
    EXPECT_GT(moves, grains / 20) << "grains that changed rank over the run";
    EXPECT_LT(moves, 100 * grains) << "grains that changed rank: more than a stirred bed can";
    EXPECT_GT(held, 0) << "ghosts held over the run";
  }
  return expected_history;
}

TEST(DemRanks, BedOnRanksMatchesOneRankBitForBit3D) {
  ranks_match_one_rank<3>(5000);
}
TEST(DemRanks, BedOnRanksMatchesOneRankBitForBit2D) {
  ranks_match_one_rank<2>(5000);
}

// Moving walls (a wall at constant speed and a servo wall): their loads are sums over the
// grains of every rank, which every rank needs to move its walls alike. Besides one rank's bits,
// the test checks that the walls did something: the top came down, the servo wall came in,
// and both carried grains.
template <int D>
void moving_walls_match_one_rank(int steps) {
  const std::vector<std::vector<Real>> h = ranks_match_one_rank<D>(steps, moving_walls<D>());
  const auto bed = make_bed<D>(moving_walls<D>());
  const std::vector<std::string> cols = bed->history_columns();
  ASSERT_EQ(cols.size(), 8u);  // top, then right: position, velocity, force, stress
  EXPECT_EQ(cols[0], "bed_wall_top_position_m");
  EXPECT_EQ(cols[7], "bed_wall_right_stress_pa");
  ASSERT_FALSE(h.empty());
  const Real dt = 0.5 * bed->stable_step().dt_s;
  const Real top0 = D == 3 ? 0.06 : 0.12;
  EXPECT_NEAR(h.back()[0], top0 - 0.5 * steps * dt, 1e-9) << "the top wall's position";
  EXPECT_TRUE(std::any_of(h.begin(), h.end(), [](const auto& row) { return row[2] > 0; }))
      << "the top wall met no grain at any check";
  // The servo wall: below its target (the grains burst away from it) it comes in at its
  // largest speed, and it carried them at some checks.
  const Real right0 = D == 3 ? 0.054 : 0.144;
  EXPECT_LT(h.back()[4], right0 - 0.1 * 0.5 * steps * dt) << "the servo wall did not come in";
  EXPECT_TRUE(std::any_of(h.begin(), h.end(), [](const auto& row) { return row[6] > 0; }))
      << "the servo wall met no grain at any check";
}

TEST(DemRanks, MovingWallsOnRanksMatchOneRankBitForBit2D) {
  moving_walls_match_one_rank<2>(5000);
}
TEST(DemRanks, MovingWallsOnRanksMatchOneRankBitForBit3D) {
  moving_walls_match_one_rank<3>(3000);
}

}  // namespace
}  // namespace crater::dem::detail
