// Cell-list neighbour search throughput.
//
// Points: n uniform random points (Poisson, random order) in a square/cube of side
// s * n^(1/D), i.e. mean spacing s = 1. Radius 2 s in 2D (pi * 4 = 12.6 neighbours per point)
// and 1.93 s in 3D (4/3 pi 1.93^3 = 30.1), fewer at the box boundary.
// Point order: "Random" as generated; "Sorted" re-ordered with cell_sort_order at the search
// radius, the state a part is in right after its periodic re-sort; "Moved" sorted, then every
// point displaced by up to 0.05 s per axis, as some steps after a re-sort. The list is reused
// across iterations, as in the time loop.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "neighbors/cell_grid.hpp"
#include "neighbors/neighbor_list.hpp"

namespace {

using crater::Index;
using crater::Real;
using crater::Vec;
namespace nb = crater::neighbors;

template <int D>
constexpr Real kRadius = D == 2 ? 2.0 : 1.93;

enum class Order { Random, Sorted, Moved };

template <int D>
std::vector<Vec<D>> random_points(Index n, Order order) {
  const Real side = std::pow(static_cast<Real>(n), Real(1) / D);
  std::mt19937_64 rng(20240601 + D);
  std::uniform_real_distribution<Real> u(0, side);
  std::vector<Vec<D>> x(static_cast<std::size_t>(n));
  for (auto& p : x) {
    for (int k = 0; k < D; ++k) {
      p[k] = u(rng);
    }
  }
  if (order != Order::Random) {
    const std::vector<Index> perm = nb::cell_sort_order<D>(x, kRadius<D>);
    std::vector<Vec<D>> y(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      y[i] = x[static_cast<std::size_t>(perm[i])];
    }
    x.swap(y);
  }
  if (order == Order::Moved) {
    std::uniform_real_distribution<Real> du(-0.05, 0.05);
    for (auto& p : x) {
      for (int k = 0; k < D; ++k) {
        p[k] += du(rng);
      }
    }
  }
  return x;
}

template <int D, Order kOrder>
void BM_NeighborList(benchmark::State& state) {
  const Index n = state.range(0);
  const std::vector<Vec<D>> x = random_points<D>(n, kOrder);
  nb::NeighborList list;
  for (auto _ : state) {
    nb::build_neighbor_list<D>(x, kRadius<D>, nb::Pairs::Full, list);
    benchmark::DoNotOptimize(list.indices.data());
    benchmark::ClobberMemory();
  }
  state.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["nbrs_per_pt"] = static_cast<double>(list.total_pairs()) / static_cast<double>(n);
}

template <int D>
void BM_NeighborCellSortOrder(benchmark::State& state) {
  const Index n = state.range(0);
  const std::vector<Vec<D>> x = random_points<D>(n, Order::Random);
  for (auto _ : state) {
    std::vector<Index> order = nb::cell_sort_order<D>(x, kRadius<D>);
    benchmark::DoNotOptimize(order.data());
  }
  state.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
}

// A cross list (a contact's candidates): the queries a, in their order at the search radius,
// against a second set b of as many points in the same box, in its own order: "SameOrder"
// sorted at the search radius (the grid's order), "OtherOrder" sorted at 0.37 of it (a finer
// part's order, e.g. a charge's SPH particles against the soil's grains), which the search's
// grid does not follow.
template <int D, bool kSameOrder>
void BM_CrossList(benchmark::State& state) {
  const Index n = state.range(0);
  const std::vector<Vec<D>> a = random_points<D>(n, Order::Sorted);
  std::vector<Vec<D>> b = random_points<D>(n, Order::Random);
  for (auto& p : b)
    p.reverseInPlace();  // other points than a's, in the same box
  const std::vector<Index> perm =
      nb::cell_sort_order<D>(b, kSameOrder ? kRadius<D> : Real(0.37) * kRadius<D>);
  std::vector<Vec<D>> sorted(b.size());
  for (std::size_t i = 0; i < b.size(); ++i)
    sorted[i] = b[static_cast<std::size_t>(perm[i])];
  nb::NeighborList list;
  for (auto _ : state) {
    nb::build_cross_list<D>(a, sorted, kRadius<D>, list);
    benchmark::DoNotOptimize(list.indices.data());
    benchmark::ClobberMemory();
  }
  state.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["nbrs_per_pt"] = static_cast<double>(list.total_pairs()) / static_cast<double>(n);
}

void sizes(benchmark::internal::Benchmark* b) {
  b->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK(BM_NeighborList<2, Order::Random>)->Name("BM_NeighborList2D/random")->Apply(sizes);
BENCHMARK(BM_NeighborList<2, Order::Sorted>)->Name("BM_NeighborList2D/sorted")->Apply(sizes);
BENCHMARK(BM_NeighborList<2, Order::Moved>)->Name("BM_NeighborList2D/moved")->Apply(sizes);
BENCHMARK(BM_NeighborList<3, Order::Random>)->Name("BM_NeighborList3D/random")->Apply(sizes);
BENCHMARK(BM_NeighborList<3, Order::Sorted>)->Name("BM_NeighborList3D/sorted")->Apply(sizes);
BENCHMARK(BM_NeighborList<3, Order::Moved>)->Name("BM_NeighborList3D/moved")->Apply(sizes);
BENCHMARK(BM_CrossList<2, true>)->Name("BM_CrossList2D/same_order")->Apply(sizes);
BENCHMARK(BM_CrossList<2, false>)->Name("BM_CrossList2D/other_order")->Apply(sizes);
BENCHMARK(BM_CrossList<3, true>)->Name("BM_CrossList3D/same_order")->Apply(sizes);
BENCHMARK(BM_CrossList<3, false>)->Name("BM_CrossList3D/other_order")->Apply(sizes);
BENCHMARK(BM_NeighborCellSortOrder<2>)->Name("BM_NeighborCellSortOrder2D")->Apply(sizes);
BENCHMARK(BM_NeighborCellSortOrder<3>)->Name("BM_NeighborCellSortOrder3D")->Apply(sizes);

}  // namespace
