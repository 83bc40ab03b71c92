// The candidate lists a pairing keeps between steps (src/contact/candidates.hpp). The reference
// is a brute-force search over every pair with the neighbour search's own distance: at every
// step of a random walk the kept list must hold every pair within the reach, its rows
// ascending; it must be rebuilt when a set is renumbered, and the searches that use it must
// find exactly the hits of a fresh list.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <random>
#include <span>
#include <stdexcept>
#include <vector>

#include "contact/candidates.hpp"
#include "contact/face_search.hpp"
#include "contact/particle_particle.hpp"

namespace crater::contact {
namespace {

template <int D>
std::vector<Vec<D>> random_points(std::mt19937_64& rng, Index n, Real size) {
  std::uniform_real_distribution<Real> u(0, size);
  std::vector<Vec<D>> x(static_cast<std::size_t>(n));
  for (auto& p : x)
    for (int d = 0; d < D; ++d)
      p[d] = u(rng);
  return x;
}

// Each point moves by up to `step` per axis at random, and all by `drift` along x.
template <int D>
void walk(std::mt19937_64& rng, std::vector<Vec<D>>& x, Real step, Real drift = 0) {
  std::uniform_real_distribution<Real> u(-step, step);
  for (auto& p : x) {
    for (int d = 0; d < D; ++d)
      p[d] += u(rng);
    p[0] += drift;
  }
}

std::vector<std::int64_t> iota_ids(std::size_t n) {
  std::vector<std::int64_t> ids(n);
  for (std::size_t i = 0; i < n; ++i)
    ids[i] = static_cast<std::int64_t>(i);
  return ids;
}

// Every pair within `reach` (by the search's distance) is in the list, and rows ascend.
template <int D>
void expect_holds_every_pair(const neighbors::NeighborList& list, const std::vector<Vec<D>>& a,
                             const std::vector<Vec<D>>& b, Real reach) {
  ASSERT_EQ(list.size(), static_cast<Index>(a.size()));
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto row = list.of(static_cast<Index>(i));
    ASSERT_TRUE(std::is_sorted(row.begin(), row.end())) << "row " << i;
    for (std::size_t j = 0; j < b.size(); ++j)
      if (search_distance_sq<D>(b[j], a[i]) <= reach * reach) {
        ASSERT_TRUE(std::binary_search(row.begin(), row.end(), static_cast<Index>(j)))
            << "pair (" << i << ", " << j << ") within the reach is missing";
      }
  }
}

template <int D>
void kept_list_holds_every_pair() {
  std::mt19937_64 rng(42);
  constexpr Real kReach = 0.05;
  std::vector<Vec<D>> a = random_points<D>(rng, 300, 1.0);
  std::vector<Vec<D>> b = random_points<D>(rng, 200, 1.0);
  const std::vector<std::int64_t> ids_a = iota_ids(a.size()), ids_b = iota_ids(b.size());
  CrossCandidates<D> kept;
  constexpr int kSteps = 200;
  for (int step = 0; step < kSteps; ++step) {
    const auto& list = kept.find(a, {.ids = ids_a, .revision = 0, .known = true}, b,
                                 {.ids = ids_b, .revision = 0, .known = true}, kReach);
    expect_holds_every_pair<D>(list, a, b, kReach);
    walk<D>(rng, a, 2e-4, 1e-4);
    walk<D>(rng, b, 2e-4, -1e-4);
  }
  // The sets drift apart by 0.2 mm a step (and jitter by up to 0.2 mm per axis): the margin
  // of a quarter of the reach, 12.5 mm, lasts some fifty steps. The list is kept, and rebuilt.
  EXPECT_GT(kept.builds(), 1);
  EXPECT_LT(kept.builds(), kSteps / 5);
}

TEST(CrossCandidates, KeptListHoldsEveryPairWithinTheReach2D) {
  kept_list_holds_every_pair<2>();
}
TEST(CrossCandidates, KeptListHoldsEveryPairWithinTheReach3D) {
  kept_list_holds_every_pair<3>();
}

TEST(CrossCandidates, RebuiltWhenTheSecondSetIsRenumberedOrTheReachGrows) {
  std::mt19937_64 rng(7);
  std::vector<Vec<2>> a = random_points<2>(rng, 100, 1.0);
  std::vector<Vec<2>> b = random_points<2>(rng, 50, 1.0);
  std::vector<std::int64_t> ids_a = iota_ids(a.size());
  CrossCandidates<2> kept;
  auto find = [&](std::uint64_t revision_b, Real reach) {
    return kept.find(a, {.ids = ids_a, .revision = 0, .known = true}, b,
                     {.ids = {}, .revision = revision_b, .known = true}, reach);
  };
  find(0, 0.1);
  find(0, 0.1);
  EXPECT_EQ(kept.builds(), 1) << "nothing moved: the list is kept";
  // Two particles re-sorted: their positions swap with their ids, so each keeps its row.
  std::swap(a[3], a[4]);
  std::swap(ids_a[3], ids_a[4]);
  expect_holds_every_pair<2>(find(0, 0.1), a, b, 0.1);
  EXPECT_EQ(kept.builds(), 1) << "the first set's rows are kept by id";
  EXPECT_EQ(kept.rows_searched(), 0);
  find(1, 0.1);
  EXPECT_EQ(kept.builds(), 2) << "a new revision of the surface is rebuilt";
  a.pop_back();
  ids_a.pop_back();
  expect_holds_every_pair<2>(find(1, 0.1), a, b, 0.1);
  EXPECT_EQ(kept.builds(), 2) << "a particle removed: the others keep their rows";
  // One particle jumps by more than the margin: its row alone is searched again.
  a[10] += Vec<2>(0.2, 0.1);
  expect_holds_every_pair<2>(find(1, 0.1), a, b, 0.1);
  EXPECT_EQ(kept.builds(), 2);
  EXPECT_EQ(kept.rows_searched(), 1);
  find(1, 0.12);
  EXPECT_EQ(kept.builds(), 2) << "a reach grown within the margin (0.125) is covered";
  expect_holds_every_pair<2>(find(1, 0.13), a, b, 0.13);
  EXPECT_EQ(kept.builds(), 3) << "a reach past the margin is rebuilt";
  // The second set renumbered by its ids (a particle set on that side) is rebuilt.
  std::vector<std::int64_t> ids_b = iota_ids(b.size());
  auto find_ids = [&] {
    return kept.find(a, {.ids = ids_a, .revision = 0, .known = true}, b,
                     {.ids = ids_b, .revision = 0, .known = true}, 0.13);
  };
  find_ids();
  EXPECT_EQ(kept.builds(), 4);
  std::swap(b[0], b[1]);
  std::swap(ids_b[0], ids_b[1]);
  expect_holds_every_pair<2>(find_ids(), a, b, 0.13);
  EXPECT_EQ(kept.builds(), 5);
  // Without ids nothing tells a re-sort apart: never kept.
  kept.find(a, {}, b, {.ids = {}, .revision = 1, .known = true}, 0.13);
  kept.find(a, {}, b, {.ids = {}, .revision = 1, .known = true}, 0.13);
  EXPECT_EQ(kept.builds(), 7);
}

// A contact zone's view on ranks: a different subset of a large set at every step (in the set's
// order), against a second set that barely moves. The list holds every pair at every step, and
// the rows of the points that stay are kept.
// `id_stride`: the ids of point i is i * id_stride (1: a dense range, looked up in a table;
// 1000: spread, looked up by binary search).
template <int D>
void view_keeps_its_rows(std::int64_t id_stride) {
  SCOPED_TRACE(::testing::Message() << "ids i * " << id_stride);
  std::mt19937_64 rng(11);
  constexpr Real kReach = 0.05;
  std::vector<Vec<D>> all = random_points<D>(rng, 2000, 1.0);
  std::vector<Vec<D>> b = random_points<D>(rng, 300, 1.0);
  std::bernoulli_distribution leaves(0.05);
  std::vector<char> in(all.size(), 1);
  CrossCandidates<D> kept;
  constexpr int kSteps = 100;
  Index rows = 0;
  for (int step = 0; step < kSteps; ++step) {
    // About 5 % of the points leave the view and as many come back.
    for (auto& v : in)
      if (leaves(rng)) v = !v;
    std::vector<Vec<D>> a;
    std::vector<std::int64_t> ids;
    for (std::size_t i = 0; i < all.size(); ++i)
      if (in[i]) {
        a.push_back(all[i]);
        ids.push_back(static_cast<std::int64_t>(i) * id_stride);
      }
    rows += static_cast<Index>(a.size());
    const auto& list = kept.find(a, {.ids = ids, .revision = 0, .known = true}, b,
                                 {.ids = {}, .revision = 0, .known = true}, kReach);
    expect_holds_every_pair<D>(list, a, b, kReach);
    walk<D>(rng, all, 2e-4);
    walk<D>(rng, b, 5e-5);
  }
  EXPECT_LT(kept.builds(), kSteps / 5) << "the view's changes keep the rows that stay";
  EXPECT_GT(kept.rows_searched(), 0);
  EXPECT_LT(kept.rows_searched(), rows / 5) << "only the rows of points new to the view";
}

TEST(CrossCandidates, AViewOfOtherPointsEveryStepKeepsItsRows2D) {
  for (const std::int64_t stride : {1, 1000})
    view_keeps_its_rows<2>(stride);
}
TEST(CrossCandidates, AViewOfOtherPointsEveryStepKeepsItsRows3D) {
  for (const std::int64_t stride : {1, 1000})
    view_keeps_its_rows<3>(stride);
}

// NearCandidates: the points with candidates ascending, none with an empty row, and, with the
// others given empty rows, every pair within the reach held (expect_holds_every_pair).
template <int D>
void expect_near_holds_every_pair(const NearRows& rows, const std::vector<Vec<D>>& a,
                                  const std::vector<Vec<D>>& b, Real reach) {
  ASSERT_TRUE(std::is_sorted(rows.point.begin(), rows.point.end()));
  ASSERT_EQ(rows.rows.size(), rows.point.size());
  neighbors::NeighborList all;
  all.offsets.assign(a.size() + 1, 0);
  std::size_t k = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (k < rows.point.size() && rows.point[k] == static_cast<Index>(i)) {
      const auto row = rows.of(k++);
      ASSERT_FALSE(row.empty()) << "point " << i << " has an empty row";
      all.indices.insert(all.indices.end(), row.begin(), row.end());
    }
    all.offsets[i + 1] = static_cast<Index>(all.indices.size());
  }
  ASSERT_EQ(k, rows.point.size()) << "rows of points outside the set";
  expect_holds_every_pair<D>(all, a, b, reach);
}

// A bed of grains that walk and are re-sorted at random every few steps (their ids travel
// with them) and now and then lose a grain, against a surface that drifts: the rows hold
// every pair at every step, the re-sorts keep them, and only the points that moved past the
// margin are searched again.
template <int D>
void near_rows_follow_ids() {
  std::mt19937_64 rng(5);
  constexpr Real kReach = 0.05;
  std::vector<Vec<D>> a = random_points<D>(rng, 1500, 1.0);
  std::vector<Vec<D>> b = random_points<D>(rng, 60, 1.0);
  for (auto& p : b)
    p[D - 1] = 0.5 + 0.05 * p[D - 1];  // a layer across the bed: few grains are near it
  std::vector<std::int64_t> ids = iota_ids(a.size());
  NearCandidates<D> kept;
  constexpr int kSteps = 150;
  Index rows = 0;
  for (int step = 0; step < kSteps; ++step) {
    if (step % 7 == 3) {  // a re-sort
      std::vector<std::size_t> order(a.size());
      for (std::size_t i = 0; i < order.size(); ++i)
        order[i] = i;
      std::shuffle(order.begin(), order.end(), rng);
      std::vector<Vec<D>> a2(a.size());
      std::vector<std::int64_t> ids2(a.size());
      for (std::size_t i = 0; i < order.size(); ++i) {
        a2[i] = a[order[i]];
        ids2[i] = ids[order[i]];
      }
      a = std::move(a2);
      ids = std::move(ids2);
    }
    if (step % 11 == 5) {  // a grain leaves
      a.erase(a.begin() + 17);
      ids.erase(ids.begin() + 17);
    }
    const NearRows& near = kept.find(a, {.ids = ids, .revision = 0, .known = true}, b,
                                     {.ids = {}, .revision = 0, .known = true}, kReach);
    expect_near_holds_every_pair<D>(near, a, b, kReach);
    rows += static_cast<Index>(a.size());
    walk<D>(rng, a, 2e-4);
    walk<D>(rng, b, 5e-5, 2e-4);
  }
  EXPECT_GT(kept.builds(), 1) << "the surface drifts past the margin: rebuilt";
  EXPECT_LT(kept.builds(), kSteps / 10) << "re-sorts and removals keep the rows";
  EXPECT_LT(kept.rows_searched(), rows / 20) << "only points that moved past the margin";
}

TEST(NearCandidates, RowsHoldEveryPairAcrossReSortsAndRemovals2D) {
  near_rows_follow_ids<2>();
}
TEST(NearCandidates, RowsHoldEveryPairAcrossReSortsAndRemovals3D) {
  near_rows_follow_ids<3>();
}

TEST(NearCandidates, RebuiltWhenTheSecondSetChangesOrTheReachGrows) {
  std::mt19937_64 rng(9);
  std::vector<Vec<2>> a = random_points<2>(rng, 200, 1.0);
  std::vector<Vec<2>> b = random_points<2>(rng, 50, 1.0);
  std::vector<std::int64_t> ids = iota_ids(a.size());
  NearCandidates<2> kept;
  auto find = [&](std::uint64_t revision_b, Real reach) -> const NearRows& {
    return kept.find(a, {.ids = ids, .revision = 0, .known = true}, b,
                     {.ids = {}, .revision = revision_b, .known = true}, reach);
  };
  find(0, 0.1);
  find(0, 0.1);
  EXPECT_EQ(kept.builds(), 1) << "nothing moved: the rows are kept";
  EXPECT_EQ(kept.rows_searched(), 0);
  // One point jumps by more than the margin: its row alone is searched again.
  a[10] += Vec<2>(0.2, 0.1);
  expect_near_holds_every_pair<2>(find(0, 0.1), a, b, 0.1);
  EXPECT_EQ(kept.builds(), 1);
  EXPECT_EQ(kept.rows_searched(), 1);
  // A point with an id new to the set (in the table's range, then beyond it).
  a.push_back(Vec<2>(0.5, 0.5));
  ids.push_back(0);
  ids[0] = 200;  // the old id 0 left; 200 is past the table's range
  expect_near_holds_every_pair<2>(find(0, 0.1), a, b, 0.1);
  EXPECT_EQ(kept.builds(), 2) << "an id past the table: a new build";
  find(1, 0.1);
  EXPECT_EQ(kept.builds(), 3) << "a new revision of the surface is rebuilt";
  find(1, 0.12);
  EXPECT_EQ(kept.builds(), 3) << "a reach grown within the margin (0.125) is covered";
  expect_near_holds_every_pair<2>(find(1, 0.13), a, b, 0.13);
  EXPECT_EQ(kept.builds(), 4) << "a reach past the margin is rebuilt";
  // Ids too sparse for a table, and no ids at all: the rows of a list in the set's order.
  std::vector<std::int64_t> sparse(a.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    sparse[i] = static_cast<std::int64_t>(i) * 1000;
  expect_near_holds_every_pair<2>(kept.find(a, {.ids = sparse, .revision = 0, .known = true}, b,
                                            {.ids = {}, .revision = 1, .known = true}, 0.13),
                                  a, b, 0.13);
  expect_near_holds_every_pair<2>(
      kept.find(a, {}, b, {.ids = {}, .revision = 1, .known = true}, 0.13), a, b, 0.13);
  // A point that is not finite is reported as the search reports it.
  a[3][0] = std::numeric_limits<Real>::quiet_NaN();
  EXPECT_THROW(find(1, 0.13), std::invalid_argument);
}

// Grains on a plate's top surface (a row of segments, 2D) and particles against grains: with
// the kept lists the searches find the hits and pairs of fresh lists, bit for bit.
TEST(CrossCandidates, SearchesFindTheHitsOfAFreshList) {
  constexpr int D = 2;
  std::mt19937_64 rng(3);
  // The surface: nodes at y = 0 along x in [0, 1], faces with the outward normal +y.
  std::vector<Vec<D>> nodes;
  for (int k = 0; k <= 50; ++k)
    nodes.push_back(Vec<D>(0.02 * k, 0.0));
  std::vector<std::array<Index, 2>> faces;
  for (Index k = 0; k < 50; ++k)
    faces.push_back({k + 1, k});  // t = x1 - x0 = -x: normal (t_y, -t_x) = +y
  const std::vector<Vec<D>> node_v(nodes.size(), Vec<D>::Zero());
  const std::vector<Real> node_m(nodes.size(), 1.0);
  const std::vector<Index> face_element(faces.size(), 0);
  const std::vector<Real> face_k(faces.size(), 1.0);
  parts::ContactSurface<D> surf{.node_position = &nodes,
                                .node_velocity = &node_v,
                                .node_mass = &node_m,
                                .faces = &faces,
                                .face_element = &face_element,
                                .face_stiffness = &face_k,
                                .revision = 0};
  // Grains of radius 5 mm in a layer just above it, and a second set above them.
  std::uniform_real_distribution<Real> ux(0, 1), uy(-0.004, 0.03);
  std::vector<Vec<D>> grains(400), gas(150);
  for (auto& g : grains)
    g = Vec<D>(ux(rng), uy(rng));
  for (auto& g : gas)
    g = Vec<D>(ux(rng), uy(rng) + 0.01);
  const std::vector<Real> r_grain(grains.size(), 0.005), r_gas(gas.size(), 0.003);
  const std::vector<Vec<D>> v_grain(grains.size(), Vec<D>::Zero()), v_gas(gas.size());
  const std::vector<Real> m_grain(grains.size(), 1.0), m_gas(gas.size(), 1.0);
  const std::vector<std::int64_t> id_grain = iota_ids(grains.size()), id_gas = iota_ids(gas.size());
  const parts::ContactPoints<D> pg{.position = &grains,
                                   .velocity = &v_grain,
                                   .mass = &m_grain,
                                   .radius = &r_grain,
                                   .id = &id_grain};
  const parts::ContactPoints<D> ps{
      .position = &gas, .velocity = &v_gas, .mass = &m_gas, .radius = &r_gas, .id = &id_gas};
  // The grains as a contact zone's view on ranks (its own particles marked): the kept list's
  // rows are then the grains', and the pairs must still come in the charge's order.
  const std::vector<char> own(grains.size(), 1);
  parts::ContactPoints<D> pg_zone = pg;
  pg_zone.own = &own;
  CrossCandidates<D> kept_faces, kept_pairs, kept_zone;
  NearCandidates<D> near_faces;
  Index hits = 0, pairs = 0;
  for (int step = 0; step < 100; ++step) {
    const auto fresh = particle_face_hits<D>(pg, surf);
    const auto from_kept = particle_face_hits<D>(pg, surf, &kept_faces);
    ASSERT_EQ(fresh.size(), from_kept.size()) << "step " << step;
    for (std::size_t q = 0; q < fresh.size(); ++q) {
      EXPECT_EQ(fresh[q].body, from_kept[q].body);
      EXPECT_EQ(fresh[q].face, from_kept[q].face);
      EXPECT_EQ(fresh[q].overlap, from_kept[q].overlap);  // bit for bit
    }
    const auto from_near = particle_face_hits<D>(pg, surf, near_faces);
    ASSERT_EQ(fresh.size(), from_near.size()) << "step " << step;
    for (std::size_t q = 0; q < fresh.size(); ++q) {
      EXPECT_EQ(fresh[q].body, from_near[q].body);
      EXPECT_EQ(fresh[q].face, from_near[q].face);
      EXPECT_EQ(fresh[q].overlap, from_near[q].overlap);
      EXPECT_EQ(fresh[q].n, from_near[q].n);
    }
    const auto p_fresh = ParticleParticle<D>::pairs(ps, pg);
    const auto p_kept = ParticleParticle<D>::pairs(ps, pg, &kept_pairs);
    ASSERT_EQ(p_fresh.size(), p_kept.size()) << "step " << step;
    for (std::size_t q = 0; q < p_fresh.size(); ++q) {
      EXPECT_EQ(p_fresh[q].a, p_kept[q].a);
      EXPECT_EQ(p_fresh[q].b, p_kept[q].b);
      EXPECT_EQ(p_fresh[q].overlap, p_kept[q].overlap);
    }
    const auto p_zone = ParticleParticle<D>::pairs(ps, pg_zone, &kept_zone);
    ASSERT_EQ(p_fresh.size(), p_zone.size()) << "step " << step;
    for (std::size_t q = 0; q < p_fresh.size(); ++q) {
      EXPECT_EQ(p_fresh[q].a, p_zone[q].a);
      EXPECT_EQ(p_fresh[q].b, p_zone[q].b);
      EXPECT_EQ(p_fresh[q].overlap, p_zone[q].overlap);
      EXPECT_EQ(p_fresh[q].d, p_zone[q].d);
    }
    hits += static_cast<Index>(fresh.size());
    pairs += static_cast<Index>(p_fresh.size());
    walk<D>(rng, grains, 3e-4);
    walk<D>(rng, gas, 3e-4);
    walk<D>(rng, nodes, 1e-4);
  }
  EXPECT_GT(hits, 1000) << "the case must have contacts to compare";
  EXPECT_GT(pairs, 1000);
  EXPECT_LT(kept_faces.builds(), 50);
  EXPECT_LT(kept_pairs.builds(), 50);
  EXPECT_LT(kept_zone.builds(), 50);
  EXPECT_LT(near_faces.builds(), 50);
}

}  // namespace
}  // namespace crater::contact
