// FEM element-loop throughput (src/fem/explicit_solid.hpp): one iteration is one
// compute_internal_forces() (kinematics, stress update, hourglass, bulk viscosity, per-node
// gather) plus the central-difference node update v += \Delta t f / m, x += \Delta t v over all
// nodes, as one step of the time loop without contact or output.
// items_per_second = element-steps per second (elements x iterations / wall time).
//
// Cases
//   BM_FemForcesQ4JohnsonCook  the paper's steel plate, 0.2 m x 0.02 m, 400 x 40 plane-strain
//       Q4 (16,000 elements, 0.5 mm), Johnson-Cook with the paper's Table 3 constants
//       (materials::paper_steel_johnson_cook), \rho = 7850 kg/m^3, no damage. Initial velocity
//       v_y = V sin(\pi x / L), V = 100 m/s: a bending field with a surface strain rate
//       \pi^2 V (H/2) / L^2 ~ 250 /s, so the outer fibres pass the yield strain A/E = 2.5e-4
//       within ~15 steps and the radial return runs in a large share of the elements.
//   BM_FemForcesHex8Elastic / BM_FemForcesHex8JohnsonCook  a steel cube of 47^3 = 103,823 Hex8
//       (1 mm), elastic (E = 200 GPa, \nu = 0.3) or the same Johnson-Cook steel. Initial
//       velocity v = V (sin(\pi y/L), sin(\pi z/L), sin(\pi x/L)), V = 5 m/s: shear rates up to
//       \pi V / L ~ 330 /s; the Johnson-Cook cube yields within ~10 steps.
// Both: viscous hourglass control 0.1, bulk viscosity at its defaults, \Delta t = 0.5 x the
// initial stable step, no boundary conditions (free body). Before timing, kWarmup = 20 steps
// bring the body into its plastic state; that state is saved and restored (outside the timing)
// every kReset = 50 iterations, so every timed step lies in the same window of steps 20-70 of
// the motion (the work per step does not depend on how many iterations the library picks, and
// long runs never drift into large distortions). The counter `yielding` is the share of
// elements whose plastic strain grew in one step after the timed loop; `threads` is
// omp_get_max_threads().
//
// Threads: the element and node loops are OpenMP (parallel/parallel.hpp); the thread count is
// OMP_NUM_THREADS. Run
//   OMP_NUM_THREADS=1 build/release/bench/crater_bench_kernels --benchmark_filter=BM_Fem
//   OMP_NUM_THREADS=2 build/release/bench/crater_bench_kernels --benchmark_filter=BM_Fem
// or bench/run_fem.sh, which builds if needed and does both.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "fem/explicit_solid.hpp"
#include "parallel/parallel.hpp"

namespace {

using crater::Index;
using crater::Real;
using crater::Vec;
namespace fem = crater::fem;
namespace materials = crater::materials;

constexpr Real kPi = std::numbers::pi;
constexpr Real kSteelDensity = 7850.0;
constexpr int kWarmup = 20;
constexpr int kReset = 50;

fem::SolidMaterial steel(bool johnson_cook) {
  fem::SolidMaterial material;
  if (johnson_cook) {
    material.strength = materials::paper_steel_johnson_cook();
  } else {
    material.strength = materials::steel_elastic();
  }
  material.density_kg_m3 = kSteelDensity;
  material.hourglass =
      fem::HourglassParams{.form = fem::HourglassForm::kViscous, .coefficient = 0.1};
  return material;
}

/// One step of the time loop: node update with the forces of the last evaluation, then forces.
template <int D>
void step(fem::ExplicitMesh<D>& mesh, const fem::SolidMaterial& material, Real dt) {
  crater::parallel::for_each(mesh.node_count(), [&](Index i) {
    const auto u = static_cast<std::size_t>(i);
    mesh.velocity[u] += (dt / mesh.mass[u]) * mesh.internal_force[u];
    mesh.position[u] += dt * mesh.velocity[u];
  });
  const fem::ForceReport report = fem::compute_internal_forces<D>(mesh, material, dt);
  benchmark::DoNotOptimize(report.internal_energy_increment_j);
}

/// Times `step` on `mesh` (initialised, initial velocities set) and reports element-steps/s.
template <int D>
void run(benchmark::State& state, fem::ExplicitMesh<D> mesh, const fem::SolidMaterial& material) {
  fem::compute_internal_forces<D>(mesh, material, 0);
  const Real dt = 0.5 * fem::stable_time_step<D>(mesh, material);
  for (int i = 0; i < kWarmup; ++i)
    step<D>(mesh, material, dt);
  const fem::ExplicitMesh<D> warmed = mesh;
  int since_reset = 0;
  for (auto _ : state) {
    if (since_reset == kReset) {
      state.PauseTiming();
      mesh = warmed;
      since_reset = 0;
      state.ResumeTiming();
    }
    step<D>(mesh, material, dt);
    ++since_reset;
    benchmark::ClobberMemory();
  }
  const Index ne = mesh.element_count();
  state.SetItemsProcessed(static_cast<int64_t>(ne) * static_cast<int64_t>(state.iterations()));
  const std::vector<Real> before = mesh.plastic_strain;
  step<D>(mesh, material, dt);
  Index yielding = 0;
  for (Index e = 0; e < ne; ++e)
    yielding +=
        mesh.plastic_strain[static_cast<std::size_t>(e)] > before[static_cast<std::size_t>(e)];
  state.counters["elements"] = static_cast<double>(ne);
  state.counters["yielding"] = static_cast<double>(yielding) / static_cast<double>(ne);
  state.counters["threads"] = crater::parallel::max_threads();
  state.counters["dt_ns"] = dt * 1e9;
}

void BM_FemForcesQ4JohnsonCook(benchmark::State& state) {
  constexpr Real kLength = 0.2, kHeight = 0.02, kSpeed = 100.0;
  fem::StructuredMeshSpec<2> spec;
  spec.lo = Vec<2>(0, -0.5 * kHeight);
  spec.hi = Vec<2>(kLength, 0.5 * kHeight);
  spec.cells = {400, 40};
  fem::ExplicitMesh<2> mesh = fem::structured_mesh<2>(spec);
  const fem::SolidMaterial material = steel(true);
  fem::initialise<2>(mesh, material);
  for (std::size_t i = 0; i < mesh.velocity.size(); ++i)
    mesh.velocity[i] = Vec<2>(0, kSpeed * std::sin(kPi * mesh.position[i][0] / kLength));
  run<2>(state, std::move(mesh), material);
}

void hex8_block(benchmark::State& state, bool johnson_cook) {
  constexpr Index kCells = 47;
  constexpr Real kSide = 0.047, kSpeed = 5.0;
  fem::StructuredMeshSpec<3> spec;
  spec.hi = Vec<3>::Constant(kSide);
  spec.cells = {kCells, kCells, kCells};
  fem::ExplicitMesh<3> mesh = fem::structured_mesh<3>(spec);
  const fem::SolidMaterial material = steel(johnson_cook);
  fem::initialise<3>(mesh, material);
  for (std::size_t i = 0; i < mesh.velocity.size(); ++i) {
    const Vec<3> x = mesh.position[i] * (kPi / kSide);
    mesh.velocity[i] = kSpeed * Vec<3>(std::sin(x[1]), std::sin(x[2]), std::sin(x[0]));
  }
  run<3>(state, std::move(mesh), material);
}

void BM_FemForcesHex8Elastic(benchmark::State& state) {
  hex8_block(state, false);
}
void BM_FemForcesHex8JohnsonCook(benchmark::State& state) {
  hex8_block(state, true);
}

BENCHMARK(BM_FemForcesQ4JohnsonCook)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FemForcesHex8Elastic)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FemForcesHex8JohnsonCook)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
