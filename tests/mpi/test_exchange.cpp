// Entities between ranks (parallel/comm.hpp, fields/exchange.hpp), on however many ranks
// the launcher gives (ctest: 1 without a launcher, and mpirun -np 1, 2, 3, 4).
//
// Every rank builds the same global reference (positions per round, fields per id) and checks
// its own share against it, so the expected results do not depend on the rank count:
// - migration under violent motion (every entity jumps anywhere in the box each round, then all
//   collapse into a small cluster, then onto one point): the count and the ids conserved
//   exactly, every field carried bit for bit, each entity on the rank RCB gives it, each rank's
//   entities in ascending id;
// - the ghosts: exactly the other ranks' entities within the reach of the rank's box (brute
//   force over the reference), the halo fields copied bit for bit and the others zero;
// - sums over the ranks with the same bits as one sum over the whole reference in id order;
// - cuts made again by measured time (fields::rebalanced_cuts, domain.balance = "time"): entities
//   whose cost depends on where they are end up spread so that each rank's summed cost (by
//   brute force over the reference) is within the tolerance of the mean.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "fields/exchange.hpp"
#include "fields/field_set.hpp"
#include "fields/spread.hpp"
#include "parallel/comm.hpp"
#include "parallel/rcb.hpp"

namespace crater::parallel {
namespace {

using fields::Halo;
using fields::migrate;
using fields::Traffic;

bool same_bits(Real a, Real b) {
  return std::memcmp(&a, &b, sizeof(Real)) == 0;
}

// A part's store, as a method registers it: fields of each role.
template <int D>
struct Store {
  fields::FieldSet<D> set;
  std::vector<std::int64_t>& id = set.add_integer("id", "1", fields::kRestart | fields::kHalo);
  std::vector<Vec<D>>& x = set.add_vector("position", "m", fields::kRestart | fields::kHalo);
  std::vector<Real>& mass = set.add_scalar("mass", "kg", fields::kRestart | fields::kHalo);
  std::vector<SymTensor>& stress = set.add_tensor("stress", "Pa", fields::kRestart);
  std::vector<std::int64_t>& tag = set.add_integer("tag", "1", fields::kNone);
};

// The reference: what entity j carries, and where it is in round k.
struct Reference {
  Index n;
  explicit Reference(Index count) : n(count) {}

  static Real mass(std::int64_t j) { return 1e-3 * (1.0 + std::sin(0.37 * static_cast<Real>(j))); }
  static SymTensor stress(std::int64_t j) {
    SymTensor s;
    for (int c = 0; c < 6; ++c)
      s[c] = 1e6 * std::cos(static_cast<Real>(j * 6 + c));
    return s;
  }
  static std::int64_t tag(std::int64_t j) { return 7 * j + 3; }

  template <int D>
  std::vector<Vec<D>> positions(int round) const {
    std::mt19937_64 gen(1000 + static_cast<unsigned>(round));
    std::uniform_real_distribution<Real> u(0.0, 1.0);
    std::vector<Vec<D>> x(static_cast<std::size_t>(n));
    for (auto& p : x)
      for (int a = 0; a < D; ++a) {
        const Real v = u(gen);
        if (round < 4) {
          p[a] = v;  // anywhere in the unit box: most entities change rank
        } else if (round == 4) {
          p[a] = 0.3 + 1e-3 * v;  // a cluster a thousandth of the box across
        } else {
          p[a] = 0.5;  // one point: RCB cuts by index
        }
      }
    return x;
  }
};

template <int D>
void check_rounds(Index n, Real reach) {
  const Comm& comm = Comm::world();
  const Reference ref(n);
  Store<D> s;
  // Round 0's start: entity j on rank j % P, whatever its position.
  for (std::int64_t j = 0; j < n; ++j)
    if (j % comm.size() == comm.rank()) {
      s.set.resize(s.set.size() + 1);
      const auto i = static_cast<std::size_t>(s.set.size() - 1);
      s.id[i] = j;
      s.mass[i] = Reference::mass(j);
      s.stress[i] = Reference::stress(j);
      s.tag[i] = Reference::tag(j);
    }
  std::vector<Real> weight(static_cast<std::size_t>(n));
  for (std::size_t j = 0; j < weight.size(); ++j)
    weight[j] = j % 5 == 0 ? 3.0 : 1.0;  // some entities cost more (another method)

  for (int round = 0; round < 6; ++round) {
    SCOPED_TRACE("round " + std::to_string(round) + ", " + std::to_string(comm.size()) +
                 " ranks, rank " + std::to_string(comm.rank()));
    const auto x = ref.positions<D>(round);
    for (Index i = 0; i < s.set.size(); ++i)
      s.x[static_cast<std::size_t>(i)] =
          x[static_cast<std::size_t>(s.id[static_cast<std::size_t>(i)])];
    const auto owner_of = rcb<D>(x, weight, comm.size()).owner;
    std::vector<int> owner(static_cast<std::size_t>(s.set.size()));
    for (std::size_t i = 0; i < owner.size(); ++i)
      owner[i] = owner_of[static_cast<std::size_t>(s.id[i])];

    const Traffic moved = migrate(comm, s.set, owner, s.id);

    // Conservation: the count, and every id exactly once.
    EXPECT_EQ(comm.sum(s.set.size()), n);
    EXPECT_EQ(comm.sum(moved.sent), comm.sum(moved.received));
    auto ids = all_gather(comm, std::span<const std::int64_t>(s.id));
    std::sort(ids.begin(), ids.end());
    ASSERT_EQ(static_cast<Index>(ids.size()), n);
    for (std::int64_t j = 0; j < n; ++j)
      ASSERT_EQ(ids[static_cast<std::size_t>(j)], j);
    // Each entity on its owner, in ascending id, with every field bit for bit.
    for (std::size_t i = 0; i < static_cast<std::size_t>(s.set.size()); ++i) {
      const std::int64_t j = s.id[i];
      EXPECT_EQ(owner_of[static_cast<std::size_t>(j)], comm.rank());
      if (i > 0) {
        EXPECT_LT(s.id[i - 1], j);
      }
      EXPECT_TRUE(same_bits(s.mass[i], Reference::mass(j)));
      EXPECT_EQ(s.x[i], x[static_cast<std::size_t>(j)]);
      EXPECT_EQ(s.stress[i], Reference::stress(j));
      EXPECT_EQ(s.tag[i], Reference::tag(j));
    }
    // The total mass over the ranks: the bits of one sum over the reference in id order.
    Real bound = 0;
    for (std::int64_t j = 0; j < n; ++j)
      bound = std::max(bound, Reference::mass(j));
    ReproducibleSum whole(bound, n);
    for (std::int64_t j = 0; j < n; ++j)
      whole.add(Reference::mass(j));
    EXPECT_TRUE(same_bits(reproducible_sum(comm, s.mass), whole.value()));

    // The ghosts against brute force: the other ranks' entities within the reach of this
    // rank's box (the box of the positions it owns).
    Halo<D> halo;
    halo.build(comm, s.x, reach);
    Store<D> g;
    const Traffic copied = halo.exchange(comm, s.set, fields::kHalo, g.set, g.id);
    EXPECT_EQ(comm.sum(copied.sent), comm.sum(copied.received));
    Vec<D> lo = Vec<D>::Constant(1e300), hi = Vec<D>::Constant(-1e300);
    for (std::int64_t j = 0; j < n; ++j)
      if (owner_of[static_cast<std::size_t>(j)] == comm.rank()) {
        lo = lo.cwiseMin(x[static_cast<std::size_t>(j)]);
        hi = hi.cwiseMax(x[static_cast<std::size_t>(j)]);
      }
    std::vector<std::int64_t> expected;
    for (std::int64_t j = 0; j < n && s.set.size() > 0; ++j) {
      if (owner_of[static_cast<std::size_t>(j)] == comm.rank()) continue;
      Real d2 = 0;
      for (int a = 0; a < D; ++a) {
        const Real c = x[static_cast<std::size_t>(j)][a];
        const Real out = c < lo[a] ? lo[a] - c : (c > hi[a] ? c - hi[a] : 0.0);
        d2 += out * out;
      }
      if (d2 <= reach * reach) expected.push_back(j);
    }
    EXPECT_EQ(g.id, expected);
    if (comm.size() > 1 && round < 4) {
      EXPECT_GT(comm.sum(g.set.size()), 0);
    }
    for (std::size_t i = 0; i < static_cast<std::size_t>(g.set.size()); ++i) {
      const std::int64_t j = g.id[i];
      EXPECT_TRUE(same_bits(g.mass[i], Reference::mass(j)));
      EXPECT_EQ(g.x[i], x[static_cast<std::size_t>(j)]);
      EXPECT_EQ(g.stress[i], SymTensor::Zero());  // not a halo field
      EXPECT_EQ(g.tag[i], 0);
    }
  }
}

TEST(Ranks, LauncherGivesTheRankCount) {
  const Comm& comm = Comm::world();
  if (const char* n = std::getenv("OMPI_COMM_WORLD_SIZE"))
    EXPECT_EQ(comm.size(), std::atoi(n));
  else
    EXPECT_EQ(comm.size(), 1);
  EXPECT_GE(comm.rank(), 0);
  EXPECT_LT(comm.rank(), comm.size());
}

TEST(Ranks, CollectivesAreExactAndInRankOrder) {
  const Comm& comm = Comm::world();
  const int r = comm.rank(), p = comm.size();
  EXPECT_EQ(comm.sum(r + 1), static_cast<std::int64_t>(p) * (p + 1) / 2);
  EXPECT_EQ(comm.max(static_cast<Real>(r)), static_cast<Real>(p - 1));
  EXPECT_EQ(comm.min(static_cast<Real>(r) + 0.5), 0.5);
  // Equal values: the smallest id wins, whichever rank holds it.
  const auto best = comm.min_with_id({r % 2 == 0 ? 1.0 : 2.0, 100 - r});
  EXPECT_EQ(best.value, 1.0);
  EXPECT_EQ(best.id, 100 - (p - 1) / 2 * 2);
  // Rank r gives r + 1 copies of r: the concatenation comes in rank order.
  const std::vector<int> mine(static_cast<std::size_t>(r + 1), r);
  const auto all = all_gather(comm, std::span<const int>(mine));
  std::vector<int> expected;
  for (int q = 0; q < p; ++q)
    expected.insert(expected.end(), static_cast<std::size_t>(q + 1), q);
  EXPECT_EQ(all, expected);
  // gather: the same, on rank 0 alone, with each rank's byte count.
  std::vector<std::int64_t> counts;
  const auto at_root = comm.gather(std::as_bytes(std::span<const int>(mine)), &counts);
  if (comm.root()) {
    EXPECT_EQ(at_root.size(), expected.size() * sizeof(int));
    EXPECT_EQ(std::memcmp(at_root.data(), expected.data(), at_root.size()), 0);
    ASSERT_EQ(counts.size(), static_cast<std::size_t>(p));
    for (int q = 0; q < p; ++q)
      EXPECT_EQ(counts[static_cast<std::size_t>(q)],
                static_cast<std::int64_t>((q + 1) * sizeof(int)));
  } else {
    EXPECT_TRUE(at_root.empty());
    EXPECT_TRUE(counts.empty());
  }
  // all_to_all: rank r sends q bytes of value r to rank q.
  std::vector<std::vector<std::byte>> send(static_cast<std::size_t>(p));
  for (int q = 0; q < p; ++q)
    send[static_cast<std::size_t>(q)].assign(static_cast<std::size_t>(q), std::byte(r));
  const auto got = comm.all_to_all(send);
  for (int q = 0; q < p; ++q)
    EXPECT_EQ(got[static_cast<std::size_t>(q)],
              std::vector<std::byte>(static_cast<std::size_t>(r), std::byte(q)));
}

TEST(Ranks, SumHasTheBitsOfOneSumInAnySplit) {
  // Terms over 16 decades of both signs, dealt to the ranks by a hash of their index.
  const Comm& comm = Comm::world();
  const Index n = 20000;
  std::mt19937_64 gen(7);
  std::uniform_real_distribution<Real> e(-8.0, 8.0);
  std::vector<Real> terms(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < terms.size(); ++i)
    terms[i] = (i % 3 == 0 ? -1.0 : 1.0) * std::pow(10.0, e(gen));
  Real bound = 0;
  for (Real t : terms)
    bound = std::max(bound, std::abs(t));
  ReproducibleSum whole(bound, n);
  long double naive = 0;
  for (Real t : terms) {
    whole.add(t);
    naive += t;
  }
  std::vector<Real> mine;
  for (std::size_t i = 0; i < terms.size(); ++i)
    if (static_cast<int>((i * 2654435761u) % static_cast<std::size_t>(comm.size())) == comm.rank())
      mine.push_back(terms[i]);
  const Real total = reproducible_sum(comm, mine);
  EXPECT_TRUE(same_bits(total, whole.value())) << total << " against " << whole.value();
  // And it is the sum (against an 80-bit sum in index order).
  EXPECT_NEAR(total, static_cast<Real>(naive), whole.error_bound() + 1e-7);
}

TEST(Ranks, MigrationAndGhosts3D) {
  check_rounds<3>(3000, 0.08);
}

TEST(Ranks, MigrationAndGhosts2D) {
  check_rounds<2>(2000, 0.05);
}

// Entities along a strip of the unit square, the left quarter four times as costly per entity
// as the rest (grains near a charge, with more contacts); every rank measures the summed cost
// of its own as its busy time. Cuts by count leave the rank holding the costly quarter the
// busiest; cuts remade by time from the ranks' measurements converge to equal costs.
TEST(Ranks, CutsByMeasuredTimeEvenTheRanksCosts) {
  const Comm& comm = Comm::world();
  const Index n = 1200;
  std::vector<Vec<2>> x(static_cast<std::size_t>(n));
  for (Index j = 0; j < n; ++j)
    x[static_cast<std::size_t>(j)] = {(static_cast<Real>(j) + 0.5) / static_cast<Real>(n),
                                      0.1 * static_cast<Real>(j % 7) / 7.0};
  auto cost = [](const Vec<2>& p) { return p[0] < 0.25 ? 4.0 : 1.0; };
  const std::vector<Real> one(x.size(), 1.0);
  RcbTree<2> cuts =
      rcb_tree<2>(std::span<const Vec<2>>(x), std::span<const Real>(one), comm.size());
  // Each rank's summed cost under `cuts`, by brute force over the reference.
  auto costs = [&] {
    std::vector<Real> c(static_cast<std::size_t>(comm.size()), 0.0);
    for (const auto& p : x)
      c[static_cast<std::size_t>(cuts.owner(p))] += cost(p);
    return c;
  };
  auto imbalance = [](const std::vector<Real>& c) {
    Real sum = 0, most = 0;
    for (const Real v : c) {
      sum += v;
      most = std::max(most, v);
    }
    return most / (sum / static_cast<Real>(c.size()));
  };
  const Real by_count = imbalance(costs());
  if (comm.size() > 1) {
    EXPECT_GT(by_count, 1.2);
  }
  fields::BusyClock busy;
  busy.by_time = true;
  int remade = 0;
  for (int window = 0; window < 12; ++window) {
    std::vector<Vec<2>> mine;
    for (const auto& p : x)
      if (cuts.owner(p) == comm.rank()) mine.push_back(p);
    const std::vector<Real> w(mine.size(), 1.0);
    // A window too short decides nothing and goes on.
    busy.busy_s = 1.0;
    busy.steps = fields::kTimeWindowSteps - 1;
    EXPECT_FALSE(
        fields::rebalanced_cuts<2>(comm, std::span<const Vec<2>>(mine), w, nullptr, &busy));
    EXPECT_EQ(busy.steps, fields::kTimeWindowSteps - 1);
    busy.steps = fields::kTimeWindowSteps;
    busy.busy_s = costs()[static_cast<std::size_t>(comm.rank())];
    Real ratio = 0;
    auto again = fields::rebalanced_cuts<2>(comm, std::span<const Vec<2>>(mine), w, &ratio, &busy);
    EXPECT_EQ(busy.steps, 0);  // a new window
    EXPECT_NEAR(ratio, imbalance(costs()), 1e-12);
    if (!again) break;
    cuts = std::move(*again);
    ++remade;
  }
  const Real by_time = imbalance(costs());
  EXPECT_LE(by_time, 1 + fields::kRebalanceTolerance) << "after " << remade << " cuts";
  if (comm.size() > 1) {
    EXPECT_GE(remade, 1);
    // By count the same measurements decide nothing: the counts are even.
    std::vector<Vec<2>> mine;
    RcbTree<2> even =
        rcb_tree<2>(std::span<const Vec<2>>(x), std::span<const Real>(one), comm.size());
    for (const auto& p : x)
      if (even.owner(p) == comm.rank()) mine.push_back(p);
    fields::BusyClock model;
    model.busy_s = 1e3 * (comm.rank() + 1);
    model.steps = fields::kTimeWindowSteps;
    const std::vector<Real> w(mine.size(), 1.0);
    EXPECT_FALSE(
        fields::rebalanced_cuts<2>(comm, std::span<const Vec<2>>(mine), w, nullptr, &model));
  }
}

TEST(Ranks, MigrationRefusesANonRank) {
  const Comm& comm = Comm::world();
  Store<3> s;
  s.set.resize(1);
  const std::vector<int> owner{comm.size()};
  EXPECT_THROW(migrate(comm, s.set, owner, s.id), std::logic_error);
}

}  // namespace
}  // namespace crater::parallel

namespace {
// What the ranks other than the first print: their failures alone, each with its rank.
class RankFailures : public ::testing::EmptyTestEventListener {
 public:
  explicit RankFailures(int rank) : rank_(rank) {}
  void OnTestPartResult(const ::testing::TestPartResult& r) override {
    if (r.failed())
      std::fprintf(stderr, "rank %d: %s:%d: failure\n%s\n", rank_,
                   r.file_name() ? r.file_name() : "?", r.line_number(), r.summary());
  }

 private:
  int rank_;
};
}  // namespace

int main(int argc, char** argv) {
  crater::parallel::Session mpi(argc, argv);
  ::testing::InitGoogleTest(&argc, argv);
  const auto& world = crater::parallel::Comm::world();
  if (!world.root()) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
    listeners.Append(new RankFailures(world.rank()));
  }
  // The verdict is every rank's.
  const int failed = RUN_ALL_TESTS() != 0 ? 1 : 0;
  return crater::parallel::Comm::world().max(failed) > 0 ? 1 : 0;
}
