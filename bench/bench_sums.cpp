// Reductions over a part's entities: parallel::deterministic_sum (fixed blocks of 512, what the
// time loop uses today) against parallel::reproducible_sum (the same bits in any order or split,
// issue 29), over n terms spread over 24 decades. Items per second = terms summed per second.
//   build/release/bench/crater_bench_kernels --benchmark_filter=Sum
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "parallel/parallel.hpp"
#include "parallel/reproducible_sum.hpp"

namespace {

using crater::Index;
using crater::Real;

std::vector<Real> terms(Index n) {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<Real> decade(-12.0, 12.0), unit(0.5, 1.0);
  std::vector<Real> xs(static_cast<std::size_t>(n));
  for (Real& x : xs)
    x = unit(rng) * std::pow(10.0, decade(rng)) * (rng() % 2 ? 1 : -1);
  return xs;
}

void BM_DeterministicSum(benchmark::State& state) {
  const std::vector<Real> xs = terms(state.range(0));
  for (auto _ : state) {
    const Real s = crater::parallel::deterministic_sum<Real>(
        static_cast<Index>(xs.size()), [&](Index i) { return xs[static_cast<std::size_t>(i)]; });
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_ReproducibleSum(benchmark::State& state) {
  const std::vector<Real> xs = terms(state.range(0));
  for (auto _ : state) {
    const Real s = crater::parallel::reproducible_sum(
        static_cast<Index>(xs.size()), [&](Index i) { return xs[static_cast<std::size_t>(i)]; });
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

BENCHMARK(BM_DeterministicSum)->Arg(8192)->Arg(131072);
BENCHMARK(BM_ReproducibleSum)->Arg(8192)->Arg(131072);

}  // namespace
