// DEM contact-law throughput (src/dem/laws/): one iteration evaluates a fixed set of touching
// sphere pairs the way the pair loop does for each contact: geometry (normal, overlap, arms),
// relative velocity at the contact point, Hertz-Mindlin with the history spring and the
// Coulomb limit, and the history written back. No neighbour list, no memory beyond the pairs'
// arrays (which fit in the L2 cache): the law's own arithmetic, what the whole-run DEM
// benchmark (bench/run_dem.sh) spends about two thirds of its time on.
// items_per_second = contact evaluations per second. BM_DemHertzMindlinContact evaluates the
// contacts one after the other; BM_DemHertzMindlinContactBatched as the pair loop does, in
// chunks: the roots of a chunk's contacts first, so that they overlap in the processor.
//
// The pairs: kPairs = 4096 pairs of the benchmark bed's spheres (R = 2.5 mm, rho 1920, G 29 GPa,
// nu 0.2, mu 0.84, e 0.5), overlaps of 1e-5 R to 1e-3 R, velocities and spins (times R) up to
// a speed s per component, s log-uniform in 0.1 mm/s ... 0.1 m/s, random directions (seeded). After
// kWarmup sweeps the histories have reached a mix of sticking and sliding contacts (the counter
// `sliding` is the share of sliding contacts in the last sweep); the histories keep evolving while
// timed, as in a run.
//
//   build/release/bench/crater_bench_kernels --benchmark_filter=BM_Dem
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "dem/laws/contact_geometry.hpp"
#include "dem/laws/hertz_mindlin.hpp"

namespace {

using crater::Real;
using crater::Vec;
using namespace crater::dem;

constexpr int kPairs = 4096;
constexpr int kWarmup = 200;
constexpr Real kRadius = 0.0025, kDt = 4.4454e-7;

struct Pairs {
  std::vector<Vec<3>> x1, x2, v1, v2, w1, w2, xi;
  Real mass = 0;
};

Pairs make_pairs() {
  Pairs p;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<Real> unit(-1, 1), depth(1e-5, 1e-3);
  p.mass = 1920 * 4.0 / 3.0 * 3.141592653589793 * kRadius * kRadius * kRadius;
  for (int k = 0; k < kPairs; ++k) {
    Vec<3> n(unit(rng), unit(rng), unit(rng));
    n.normalize();
    const Vec<3> x1 = Vec<3>(unit(rng), unit(rng), unit(rng)) * 0.1;
    p.x1.push_back(x1);
    p.x2.push_back(x1 - (2 * kRadius - depth(rng) * kRadius) * n);
    // Speeds log-uniform over three decades: slow pairs stick, fast ones slide.
    const Real speed = 0.1 * std::pow(10.0, -3 * std::abs(unit(rng)));
    p.v1.push_back(Vec<3>(unit(rng), unit(rng), unit(rng)) * speed);
    p.v2.push_back(Vec<3>(unit(rng), unit(rng), unit(rng)) * speed);
    p.w1.push_back(Vec<3>(unit(rng), unit(rng), unit(rng)) * (speed / kRadius));
    p.w2.push_back(Vec<3>(unit(rng), unit(rng), unit(rng)) * (speed / kRadius));
    p.xi.push_back(Vec<3>::Zero());
  }
  return p;
}

// One sweep over the pairs; returns the number of sliding contacts and a checksum that keeps
// the results alive.
int sweep(const HertzMindlinParams& law, Pairs& p, Real& sink) {
  int sliding = 0;
  for (int k = 0; k < kPairs; ++k) {
    const ContactGeometry<3> g = sphere_sphere_geometry<3>(p.x1[k], kRadius, p.x2[k], kRadius);
    const RelativeVelocity<3> rel =
        relative_velocity<3>(g, BodyMotion<3>{p.v1[k], p.w1[k]}, BodyMotion<3>{p.v2[k], p.w2[k]});
    const ContactForce<3> cf =
        hertz_mindlin<3>(law, g, rel, effective_mass(p.mass, p.mass), p.xi[k], kDt);
    p.xi[k] = cf.shear_history;
    sliding += cf.sliding;
    sink += cf.force_on_1[0] + cf.torque_on_1[1] + cf.torque_on_2[2] + cf.elastic_energy +
            cf.dissipated_power;
  }
  return sliding;
}

// The same contacts in chunks of 8 as the pair loop runs them (src/dem/dem_pair_loop.cpp,
// pair_pass): the geometry and the law's roots (HertzMindlin::prepare) for the whole chunk
// and the history's rotation first, then the rest of each law (HertzMindlin::finish).
int sweep_batched(const HertzMindlinParams& law, Pairs& p, Real& sink) {
  constexpr int kChunk = 8;
  int sliding = 0;
  std::array<ContactGeometry<3>, kChunk> g;
  std::array<ContactPrep<3>, kChunk> part;
  for (int k0 = 0; k0 < kPairs; k0 += kChunk) {
    for (int c = 0; c < kChunk; ++c) {
      const int k = k0 + c;
      g[c] = sphere_sphere_geometry<3>(p.x1[k], kRadius, p.x2[k], kRadius);
      part[c] = HertzMindlin::prepare<3>(law, g[c], effective_mass(p.mass, p.mass), p.xi[k]);
    }
    for (int c = 0; c < kChunk; ++c) {
      const int k = k0 + c;
      const RelativeVelocity<3> rel = relative_velocity<3>(g[c], BodyMotion<3>{p.v1[k], p.w1[k]},
                                                           BodyMotion<3>{p.v2[k], p.w2[k]});
      const ContactForce<3> cf = HertzMindlin::finish<3>(law, g[c], rel, part[c], kDt);
      p.xi[k] = cf.shear_history;
      sliding += cf.sliding;
      sink += cf.force_on_1[0] + cf.torque_on_1[1] + cf.torque_on_2[2] + cf.elastic_energy +
              cf.dissipated_power;
    }
  }
  return sliding;
}

// Times one sweep (sweep or sweep_batched) over the pairs after kWarmup untimed ones.
template <int (*Sweep)(const HertzMindlinParams&, Pairs&, Real&)>
void run_sweeps(benchmark::State& state) {
  const ElasticMaterial sand{youngs_modulus_from_shear(29e9, 0.2), 0.2};
  const HertzMindlinParams law = hertz_mindlin_params(sand, sand, 0.5, 0.84);
  Pairs pairs = make_pairs();
  Real sink = 0;
  for (int s = 0; s < kWarmup; ++s)
    Sweep(law, pairs, sink);
  int sliding = 0;
  for (auto _ : state) {
    sliding = Sweep(law, pairs, sink);
    benchmark::DoNotOptimize(sink);
  }
  state.SetItemsProcessed(state.iterations() * kPairs);
  state.counters["sliding"] = static_cast<double>(sliding) / kPairs;
}

void BM_DemHertzMindlinContact(benchmark::State& state) {
  run_sweeps<sweep>(state);
}
void BM_DemHertzMindlinContactBatched(benchmark::State& state) {
  run_sweeps<sweep_batched>(state);
}

}  // namespace

BENCHMARK(BM_DemHertzMindlinContact)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DemHertzMindlinContactBatched)->Unit(benchmark::kMicrosecond);
