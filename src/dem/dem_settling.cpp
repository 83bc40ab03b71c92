// Packed parts (dem_part.hpp): the cache key of a settled packing, the grains of a random
// packing, and the settling run (a DemPart alone under gravity, dem_part_impl.hpp).
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "dem/dem_part.hpp"
#include "dem/dem_part_impl.hpp"

namespace crater::dem {

using parts::to_vec;

// Everything that shapes a settled packing, as text for its cache key (hex floats: exact).
template <int D>
std::string packing_key_text(const PartSettings& settings) {
  const parts::PartSetup& pc = settings.part;
  std::string s = fmt::format("crater packing v2|D={}|", D);
  auto v3 = [](const parts::Vec3& v) { return fmt::format("{:a},{:a},{:a}", v[0], v[1], v[2]); };
  const auto& g = settings.grain;
  s += fmt::format("domain={};{};g={}|", v3(pc.domain.min_m), v3(pc.domain.max_m),
                   v3(pc.domain.gravity_m_s2));
  s += fmt::format("mat={:a},{:a},{:a},{:a},{:a}|", settings.rho0_kg_m3, g.shear_modulus_pa,
                   g.poisson_ratio, g.friction, g.restitution);
  s += fmt::format("region={},{},{},{},{:a}|spacing={:a}|", static_cast<int>(pc.region.type),
                   v3(pc.region.min_m), v3(pc.region.max_m), v3(pc.region.center_m),
                   pc.region.radius_m, pc.spacing_m);
  const auto& d = settings.dem;
  s += fmt::format("dem={:a},{:a},{},{:a},{:a},{:a}|walls=", d.radius_min_m, d.radius_max_m, d.seed,
                   d.rayleigh_fraction, d.wall_friction, d.wall_restitution);
  for (const auto f : d.walls)
    s += fmt::format("{},", static_cast<int>(f));
  // Absorbing faces are rigid walls while settling (listed only when there are some, so the
  // keys of packings without them are unchanged).
  if (!d.absorbing_walls.empty()) {
    s += "|absorbing=";
    for (const auto f : d.absorbing_walls)
      s += fmt::format("{},", static_cast<int>(f));
  }
  // Symmetry planes are frictionless walls (listed only when there are some).
  if (!pc.domain.symmetry_planes.empty()) {
    s += "|symmetry=";
    for (const auto f : pc.domain.symmetry_planes)
      s += fmt::format("{},", static_cast<int>(f));
  }
  s += fmt::format("|law={},{:a},{:a},{:a},{:a},{:a},{},{:a},{:a}", static_cast<int>(d.contact),
                   d.normal_stiffness_n_m, d.shear_stiffness_n_m, d.stiffness_step_fraction,
                   d.rolling_friction, d.rolling_damping, d.rate_dependent_friction,
                   d.friction_rate_beta, d.friction_reference_strain_rate);
  if (d.hertz_row_of_spheres) s += "|hertz_2d=row_of_spheres";
  // Moving walls settle the bed where they start (listed only when one is placed).
  for (const WallMotion& m : d.wall_motion)
    if (m.position_m) s += fmt::format("|wall_at={},{:a}", static_cast<int>(m.face), *m.position_m);
  const auto& k = settings.packing;
  s += fmt::format("|packing={},{:a},{:a},{:a},{:a},{:a}|sieve=", k.method == PackingMethod::Random,
                   k.porosity, k.settle_kinetic_ratio, k.settle_max_time_s, k.settle_damping,
                   settings.safety_factor);
  for (std::size_t j = 0; j < k.sieve_diameter_m.size(); ++j)
    s += fmt::format("{:a}:{:a},", k.sieve_diameter_m[j], k.sieve_passing[j]);
  // A dense bed also depends on the bodies it is laid around, on its algorithm's version and
  // on the settling's force criterion (appended, so the other packings' keys are unchanged).
  if (k.method == PackingMethod::Dense) {
    s += fmt::format("|dense=v{},{},{:a}|bodies=", kDensePackingVersion, CRATER_VERSION,
                     k.settle_unbalanced_ratio);
    for (const parts::RegionConfig& b : pc.carving)
      s += fmt::format("{},{},{},{:a};", static_cast<int>(b.type), v3(b.min_m), v3(b.max_m),
                       b.radius_m) +
           v3(b.center_m) + ";";
  }
  return s;
}

template <int D>
std::vector<Grain<D>> random_grains(const PartSettings& settings) {
  const parts::PartSetup& pc = settings.part;
  const auto& k = settings.packing;
  const std::string key_name = fmt::format("parts[{}].packing", pc.name);
  const Real solid = (1 - k.porosity) * region_volume<D>(pc.region);
  std::vector<Real> radii =
      draw_radii<D>(k, settings.dem.radius_min_m, settings.dem.radius_max_m, solid,
                    settings.dem.seed, std::size_t{50'000'000}, pc.where, key_name);
  std::vector<Grain<D>> grains = random_packing<D>(
      pc.region, std::move(radii), to_vec<D>(pc.domain.gravity_m_s2), to_vec<D>(pc.domain.min_m),
      to_vec<D>(pc.domain.max_m), settings.dem.seed, pc.where, key_name);
  // Random addition knows nothing of the parts this one is carved around: the grains reaching
  // into them are dropped (the part's constructor keeps a packing's grains as they are).
  std::erase_if(grains, [&](const Grain<D>& q) { return parts::carved<D>(pc.carving, q.x, q.r); });
  return grains;
}

template <int D>
std::vector<Grain<D>> dense_grains(const PartSettings& settings, DensePackingReport& report) {
  const parts::PartSetup& pc = settings.part;
  const std::string key_name = fmt::format("parts[{}].packing.method", pc.name);
  if (pc.region.type != parts::RegionType::Box)
    throw InputError(pc.where, key_name,
                     "a dense packing fills a box region; give the part a box (the bodies it "
                     "is carved around may be of any shape)");
  const Vec<D> g = to_vec<D>(pc.domain.gravity_m_s2);
  int axis = -1;
  for (int d = 0; d < D; ++d)
    if (g[d] != 0) axis = axis < 0 ? d : D;
  if (axis < 0 || axis == D)
    throw InputError(pc.where, key_name,
                     "a dense packing is laid from the floor up: it needs gravity along one axis "
                     "(domain.gravity_m_s2)");
  DensePackingInput<D> in;
  for (int d = 0; d < D; ++d) {
    in.lo[d] = pc.region.min_m[static_cast<std::size_t>(d)];
    in.hi[d] = pc.region.max_m[static_cast<std::size_t>(d)];
  }
  in.up_axis = axis;
  in.up_sign = g[axis] < 0 ? 1 : -1;
  in.r_min = settings.dem.radius_min_m;
  in.r_max = settings.dem.radius_max_m;
  in.seed = settings.dem.seed;
  in.keep_clear = pc.carving;
  try {
    return dense_packing<D>(in, &report);
  } catch (const std::invalid_argument& e) {
    throw InputError(pc.where, key_name, e.what());
  } catch (const std::length_error&) {
    throw InputError(pc.where, key_name,
                     fmt::format("a dense packing of more than {} grains (the region is too "
                                 "large for the grain size); enlarge the grains or shrink the "
                                 "region",
                                 in.max_grains));
  }
}

// Settle: the part alone under gravity, with its walls, the bodies it is carved around and the
// settling damping, until the grains have had the time to fall the column's height and their
// mean kinetic energy is below settle_kinetic_ratio x m g r. A dense bed is laid in place and
// only needs its contacts loaded: no fall time, and settled once, besides the kinetic energy,
// the unbalanced force is below settle_unbalanced_ratio of the weight (static equilibrium).
template <int D>
SettledPacking<D> settle_grains(const PartSettings& settings, const std::vector<Grain<D>>* grains,
                                PackingReport& report, const parallel::Comm* spread) {
  const parts::PartSetup& pc = settings.part;
  const auto& k = settings.packing;
  const std::string key_name = fmt::format("parts[{}].packing", pc.name);
  const bool deposited = k.method == PackingMethod::Dense;
  detail::DemPart<D> part(settings, grains, k.settle_damping);
  const Vec<D> g = to_vec<D>(pc.domain.gravity_m_s2);
  Real lo = std::numeric_limits<Real>::infinity(), hi = -lo;
  for (const auto& q : part.grains()) {
    lo = std::min(lo, q.x.dot(g) / g.norm());
    hi = std::max(hi, q.x.dot(g) / g.norm());
  }
  const Real t_fall = deposited ? 0 : std::sqrt(2 * std::max(hi - lo, 0.0) / g.norm());
  // On ranks the bed is spread as a run's is (every rank built it whole), and settles with the
  // bits of one rank: the stable step, the checks and the measures are over the whole part.
  const bool ranks = spread && spread->size() > 1;
  spdlog::info("part '{}': settling {} grains under gravity (at least {:.3g} s){}", pc.name,
               part.count(), t_fall,
               ranks ? fmt::format(", spread over {} ranks", spread->size()) : std::string());
  if (ranks) part.distribute(*spread);
  Real t = 0;
  long long steps = 0;
  auto next_report = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  part.compute_forces(t);
  while (true) {
    const Real dt = settings.safety_factor * part.stable_step().dt_s;
    part.advance(t, dt);
    t += dt;
    part.compute_forces(t);
    if (auto fault = part.check())
      throw InputError(pc.where, key_name,
                       fmt::format("settling failed at t = {:.4g} s, grain {}: {}", t,
                                   fault->entity_id, fault->what));
    part.finish_step(dt);
    ++steps;
    if (steps % 200 != 0) continue;
    // A large bed settles for many minutes: say where it stands every half minute.
    bool tell = std::chrono::steady_clock::now() >= next_report;
    // The root's clock decides for every rank: the measures below are collective.
    if (ranks) tell = spread->max(tell && spread->root() ? Real(1) : Real(0)) > 0;
    if (t < t_fall && !tell) continue;
    const auto [ke, scale] = part.settling_measure();
    const Real unbalanced = deposited ? part.unbalanced_ratio() : 0;
    if (tell) {
      spdlog::info(
          "part '{}': settling, t = {:.4g} s after {} steps: kinetic energy {:.3g} x m g r "
          "(settled below {:.3g}){}",
          pc.name, t, steps, ke / scale, k.settle_kinetic_ratio,
          deposited ? fmt::format(", unbalanced force {:.3g} of the weight (below {:.3g})",
                                  unbalanced, k.settle_unbalanced_ratio)
                    : std::string());
      next_report = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    }
    if (t < t_fall) continue;
    if (ke < k.settle_kinetic_ratio * scale && unbalanced <= k.settle_unbalanced_ratio) break;
    if (t > k.settle_max_time_s)
      throw InputError(pc.where, key_name + ".settle_max_time_s",
                       fmt::format("the grains did not settle in {} s: mean kinetic energy {:.3g} "
                                   "x m g r, settled below {:.3g}{}; raise settle_max_time_s or "
                                   "settle_damping",
                                   k.settle_max_time_s, ke / scale, k.settle_kinetic_ratio,
                                   deposited ? fmt::format(" (unbalanced force {:.3g} of the "
                                                           "weight, settled below {:.3g})",
                                                           unbalanced, k.settle_unbalanced_ratio)
                                             : std::string()));
  }
  report.settle_time_s = t;
  report.settle_steps = steps;
  if (!ranks) return {part.grains(), part.contact_history()};
  // The settled bed whole on the root, as one rank holds it: the bytes of a checkpoint of the
  // spread part (gathered there), read into a part built whole. The other ranks get nothing.
  parts::StateWriter w;
  part.save_state(w);
  if (!spread->root()) return {};
  detail::DemPart<D> whole(settings, grains, k.settle_damping);
  parts::StateReader r(w.bytes(), fmt::format("part '{}': the settled packing", pc.name));
  whole.load_state(r);
  return {whole.grains(), whole.contact_history()};
}

#define CRATER_DEM_SETTLING(D)                                                                   \
  template std::string packing_key_text<D>(const PartSettings&);                                 \
  template std::vector<Grain<D>> random_grains<D>(const PartSettings&);                          \
  template std::vector<Grain<D>> dense_grains<D>(const PartSettings&, DensePackingReport&);      \
  template SettledPacking<D> settle_grains<D>(const PartSettings&, const std::vector<Grain<D>>*, \
                                              PackingReport&, const parallel::Comm*);
CRATER_DEM_SETTLING(2)
CRATER_DEM_SETTLING(3)
#undef CRATER_DEM_SETTLING

}  // namespace crater::dem
