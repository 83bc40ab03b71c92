// Assembly of the parts from the scenario; see assembly.hpp.
#include "solver/assembly.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <vector>

#include "core/error.hpp"
#include "core/hash.hpp"
#include "dem/dem_part.hpp"
#include "fem/fem_part.hpp"
#include "parallel/comm.hpp"
#include "solver/packing_cache.hpp"
#include "sph/sph_part.hpp"

namespace crater::solver {

parts::PartSetup part_setup(const io::Config& config, const io::PartConfig& part) {
  parts::PartSetup s;
  s.name = part.name;
  s.domain = config.domain;
  s.spacing_m = part.spacing_m;
  s.region = part.region;
  s.initial = part.initial;
  s.zones = part.zones;
  for (std::size_t k : part.carve)
    s.carving.push_back(config.parts[k].region);
  s.detonations = part.detonations;
  s.where = part.where;
  return s;
}

namespace {

// `walls` with the domain's symmetry planes added (after the part's own, whose order the moving
// walls' slots follow); the reader keeps a face from being in both.
std::vector<parts::Face> with_symmetry_planes(std::vector<parts::Face> walls,
                                              const parts::Domain& domain) {
  for (const parts::Face f : domain.symmetry_planes)
    walls.push_back(f);
  return walls;
}

}  // namespace

sph::PartSettings sph_settings(const io::Config& config, const io::PartConfig& part) {
  const io::MaterialConfig& m = config.materials[part.material];
  sph::Settings s = part.sph();
  // A symmetry plane is a free-slip wall: mirror images (the reader refuses no-slip walls
  // beside them).
  s.walls = with_symmetry_planes(std::move(s.walls), config.domain);
  if (!config.domain.symmetry_planes.empty()) s.wall_no_slip = false;
  return {part_setup(config, part), s, m.eos, m.rho0_kg_m3};
}

dem::PartSettings dem_settings(const io::Config& config, const io::PartConfig& part) {
  const io::MaterialConfig& m = config.materials[part.material];
  const Real settle = part.packing().settle_safety_factor;
  // A symmetry plane is a rigid wall of the grains (frictionless: DemPart::init_walls).
  dem::Settings d = part.dem();
  d.walls = with_symmetry_planes(std::move(d.walls), config.domain);
  return {part_setup(config, part),
          d,
          part.packing(),
          m.granular,
          m.rho0_kg_m3,
          settle > 0 ? settle : config.time.safety_factor};
}

fem::PartSettings fem_settings(const io::Config& config, const io::PartConfig& part) {
  const io::MaterialConfig& m = config.materials[part.material];
  return {part_setup(config, part), part.fem(), m.solid, m.rho0_kg_m3};
}

/// The scenario's contacts as contact/ takes them; per part E = 2 G (1 + nu) of its granular
/// material (0 for other materials), the stiffness of particle-particle contacts.
std::vector<contact::ContactSettings> contact_settings(const io::Config& config) {
  std::vector<contact::ContactSettings> out;
  for (const io::ContactConfig& c : config.contacts) {
    contact::ContactSettings s;
    s.parts = c.parts;
    s.penalty_scale = c.penalty_scale;
    s.friction = c.friction;
    s.damping_ratio = c.damping_ratio;
    s.surface_group = c.surface_groups;
    for (std::size_t k = 0; k < 2; ++k) {
      const auto& g = config.materials[config.parts[c.parts[k]].material].granular;
      s.grain_modulus_pa[k] = 2 * g.shear_modulus_pa * (1 + g.poisson_ratio);
    }
    out.push_back(s);
  }
  return out;
}

namespace {

// The grains of a random or dense packing, as laid (before any settling).
template <int D>
std::vector<dem::Grain<D>> laid_grains(const dem::PartSettings& settings) {
  if (settings.packing.method == dem::PackingMethod::Random) return dem::random_grains<D>(settings);
  dem::DensePackingReport r;
  std::vector<dem::Grain<D>> grains = dem::dense_grains<D>(settings, r);
  spdlog::info(
      "part '{}': dense packing of {} grains, solid fraction {:.4f} of its free {:.4g} "
      "m^{}",
      settings.part.name, r.grains, r.solid_volume / r.free_volume, r.free_volume, D);
  return grains;
}

// The user's packing cache, for scenarios whose own cache_dir cannot be written (the bundled
// scenarios of an installed crater, in a read-only <prefix>/share/crater/scenarios):
// $XDG_CACHE_HOME/crater/packings, else $HOME/.cache/crater/packings; empty if neither is set.
std::filesystem::path user_packing_cache() {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  if (xdg != nullptr && *xdg == '/') return std::filesystem::path(xdg) / "crater" / "packings";
  const char* home = std::getenv("HOME");
  if (home != nullptr && *home == '/')
    return std::filesystem::path(home) / ".cache" / "crater" / "packings";
  return {};
}

// Saves the packing in `dir` (made if missing); false, with the reason, if that fails.
template <int D>
bool try_save_packing(const std::filesystem::path& file, std::uint64_t key,
                      const dem::SettledPacking<D>& settled, std::string& why) {
  try {
    std::filesystem::create_directories(file.parent_path());
    save_packing<D>(file.string(), key, settled);
    return true;
  } catch (const std::exception& e) {
    why = e.what();
    return false;
  }
}

// The grains a packed part settles from: as laid (random, dense), or none for a lattice, which
// the part lays itself.
template <int D>
std::optional<std::vector<dem::Grain<D>>> grains_to_settle(const dem::PartSettings& settings) {
  if (settings.packing.method == dem::PackingMethod::Lattice) return std::nullopt;
  return laid_grains<D>(settings);
}

// Where a packing is cached: the scenario's cache_dir, and the user's cache.
struct PackingPlaces {
  std::uint64_t key = 0;
  std::filesystem::path file, user_dir;
  std::string file_name;
};
template <int D>
PackingPlaces packing_places(const dem::PartSettings& settings) {
  PackingPlaces p;
  p.key = fnv1a(dem::packing_key_text<D>(settings));
  p.file_name = fmt::format("{}-{:016x}.pack", settings.part.name, p.key);
  p.file = std::filesystem::path(settings.packing.cache_dir) / p.file_name;
  p.user_dir = user_packing_cache();
  return p;
}

// The part from a cached packing of these settings, or nullptr when no cache holds one.
template <int D>
std::unique_ptr<Part<D>> cached_dem_part(const dem::PartSettings& settings, std::string& used,
                                         dem::PackingReport& report) {
  const PackingPlaces at = packing_places<D>(settings);
  std::vector<std::filesystem::path> places = {at.file};
  if (!at.user_dir.empty()) places.push_back(at.user_dir / at.file_name);
  for (const auto& f : places) {
    std::string bytes = read_packing_file(f.string());
    if (auto cached = packing_from_bytes<D>(bytes, at.key)) {
      report.reused = true;
      spdlog::info("part '{}': settled packing of {} grains reused from {}", settings.part.name,
                   cached->grains.size(), f.string());
      used = std::move(bytes);
      return dem::make_dem_part<D>(settings, &cached->grains, report, &cached->contacts);
    }
  }
  return nullptr;
}

// The grains settled under gravity (dem::settle_grains; spread over the ranks of `spread` if
// given, every rank calling), saved in the cache, and the part from what was saved: so a run that
// settled starts from exactly what a reuse would. On ranks the root alone saves and builds
// (nullptr elsewhere).
template <int D>
std::unique_ptr<Part<D>> settled_dem_part(const dem::PartSettings& settings, std::string& used,
                                          dem::PackingReport& report,
                                          const parallel::Comm* spread = nullptr) {
  const std::string& name = settings.part.name;
  const auto grains = grains_to_settle<D>(settings);
  const dem::SettledPacking<D> settled =
      dem::settle_grains<D>(settings, grains ? &*grains : nullptr, report, spread);
  if (spread && !spread->root()) return nullptr;
  const PackingPlaces at = packing_places<D>(settings);
  std::filesystem::path saved = at.file;
  std::string why;
  if (!try_save_packing<D>(at.file, at.key, settled, why)) {
    std::string why_user = "neither XDG_CACHE_HOME nor HOME is set";
    if (at.user_dir.empty() ||
        !try_save_packing<D>(at.user_dir / at.file_name, at.key, settled, why_user))
      throw std::runtime_error(fmt::format(
          "part '{}': the settled packing could be saved neither in [parts.packing] cache_dir "
          "({}) nor in the user's cache ({}); set cache_dir to a writable directory",
          name, why, why_user));
    spdlog::warn(
        "part '{}': cache_dir {} cannot be written ({}); the packing goes to the user's "
        "cache {}",
        name, settings.packing.cache_dir, why, at.user_dir.string());
    saved = at.user_dir / at.file_name;
  }
  spdlog::info("part '{}': settled in {:.4g} s ({} steps); saved to {}", name, report.settle_time_s,
               report.settle_steps, saved.string());
  // Read back what was saved, so this run starts from exactly what a reuse would.
  used = read_packing_file(saved.string());
  if (auto back = packing_from_bytes<D>(used, at.key))
    return dem::make_dem_part<D>(settings, &back->grains, report, &back->contacts);
  throw std::runtime_error("could not read back the settled packing " + saved.string());
}

// A packed DEM part: its grains from the cache if it holds this packing, else generated (and
// settled under gravity with the domain's walls, then saved). The run starts from the saved
// state (positions and radii, grains at rest, and the contacts' springs) in both cases, so a
// run that settled and a run that reused give identical results. The cache is the scenario's
// cache_dir, and the user's cache where that cannot be written.
// `used` gets the bytes of the packing file the settled grains were read from (empty: built as
// laid).
template <int D>
std::unique_ptr<Part<D>> packed_dem_part(const dem::PartSettings& settings, Settling settling,
                                         std::string& used, dem::PackingReport& report) {
  if (!settings.packing.settle) {
    const std::vector<dem::Grain<D>> grains = laid_grains<D>(settings);
    return dem::make_dem_part<D>(settings, &grains, report);
  }
  if (auto part = cached_dem_part<D>(settings, used, report)) return part;
  if (settling == Settling::CachedOnly) {
    // The same grains (count, radii: the same solid fraction and stable step) before settling.
    report.unsettled = true;
    const auto grains = grains_to_settle<D>(settings);
    return dem::make_dem_part<D>(settings, grains ? &*grains : nullptr, report);
  }
  return settled_dem_part<D>(settings, used, report);
}

// The same on several MPI ranks: rank 0 alone looks in the cache (its finding decides for
// all); a packing not cached is settled by every rank together, spread as a run's bed is
// (dem::settle_grains, with one rank's bits), and rank 0 alone saves it. Rank 0 then sends the
// file's bytes with its report to the other ranks, which build the part from them: every rank
// starts from the same bits, and one process writes the cache.
template <int D>
std::unique_ptr<Part<D>> packed_dem_part(const dem::PartSettings& settings, Settling settling) {
  const parallel::Comm& comm = parallel::Comm::world();
  std::string used;
  dem::PackingReport report;
  if (comm.size() == 1 || !settings.packing.settle || settling == Settling::CachedOnly)
    return packed_dem_part<D>(settings, settling, used, report);
  std::unique_ptr<Part<D>> part;
  if (comm.root()) part = cached_dem_part<D>(settings, used, report);
  if (comm.max(part ? Real(1) : Real(0)) == 0)
    part = settled_dem_part<D>(settings, used, report, &comm);
  std::string mine;
  if (comm.root()) {
    mine.assign(reinterpret_cast<const char*>(&report), sizeof(report));
    mine += used;
  }
  const std::vector<std::byte> got =
      comm.all_gather(std::as_bytes(std::span<const char>(mine.data(), mine.size())));
  if (comm.root()) return part;
  if (got.size() < sizeof(report)) throw std::logic_error("packing: short message from rank 0");
  std::memcpy(&report, got.data(), sizeof(report));
  const std::string_view file(reinterpret_cast<const char*>(got.data()) + sizeof(report),
                              got.size() - sizeof(report));
  auto settled = packing_from_bytes<D>(file, fnv1a(dem::packing_key_text<D>(settings)));
  if (!settled) throw std::logic_error("packing: rank 0's packing does not read back");
  return dem::make_dem_part<D>(settings, &settled->grains, report, &settled->contacts);
}

}  // namespace

template <int D>
std::vector<std::unique_ptr<Part<D>>> build_parts(const io::Config& config, Settling settling) {
  std::vector<std::unique_ptr<Part<D>>> parts;
  for (std::size_t i = 0; i < config.parts.size(); ++i) {
    const io::PartConfig& pc = config.parts[i];
    if (pc.is(io::Method::Sph)) parts.push_back(sph::make_sph_part<D>(sph_settings(config, pc)));
    if (pc.is(io::Method::Fem)) {
      try {
        parts.push_back(fem::make_fem_part<D>(fem_settings(config, pc)));
      } catch (const InputError& e) {
        // A degenerate element of the mesh file: the file's line, and the scenario's key.
        if (!e.key().empty()) throw;
        throw InputError(e.where(), fmt::format("parts[{}].fem.mesh_file", i), e.what());
      }
    }
    if (!pc.is(io::Method::Dem)) continue;
    const dem::PartSettings settings = dem_settings(config, pc);
    if (settings.packing.method != dem::PackingMethod::Lattice || settings.packing.settle)
      parts.push_back(packed_dem_part<D>(settings, settling));
    else
      parts.push_back(dem::make_dem_part<D>(settings));
  }
  return parts;
}

template std::vector<std::unique_ptr<Part<2>>> build_parts<2>(const io::Config&, Settling);
template std::vector<std::unique_ptr<Part<3>>> build_parts<3>(const io::Config&, Settling);

}  // namespace crater::solver
