// libFuzzer target: the scenario parser (TOML text -> overrides -> schema validation ->
// cross-checks -> Config), and, when that is cheap, `crater check`'s construction of the parts.
//
// Expected outcomes: a Config, or an InputError (exit 2: the file is wrong). Anything else that
// escapes -- another exception, a crash, a sanitizer report, a hang, gigabytes of memory -- is a
// finding: the input goes to tests/fuzz/crashes/scenario/ once reported and fixed. So is an
// accepted scenario whose parts would hold an absurd number of entities: the
// validator must refuse those before anything is allocated (see kMaxEntities).
//
// Input: the scenario file's bytes. A line "#set dotted.key=VALUE" (a TOML comment, so the file
// still parses the same) also passes "dotted.key=VALUE" as a --set override, so the fuzzer
// reaches the override code as `crater check FILE --set ...` does.
//
// Parts are built (solver::check_scenario, exactly what `crater check` runs) only when a
// conservative estimate of what they allocate is small (kMaxBuildEntities): the validator admits
// up to 2e8 particles by design, which is legitimate for a run but not for a fuzzer iteration.
// Settled packings are never built here: settling is a simulation (seconds to minutes) and
// writes a cache file next to the scenario.
//
// Environment: CRATER_FUZZ_BUILD=0 stops at validation; CRATER_FUZZ_STATS=1 prints at exit how
// many inputs were rejected, accepted, and accepted with their parts built.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <typeinfo>
#include <vector>

#include "core/error.hpp"
#include "io/scenario/config.hpp"
#include "io/scenario/load.hpp"
#include "parts/region.hpp"
#include "solver/simulation.hpp"

namespace {

using crater::Real;
using namespace crater::io;

// Upper bound on entities (particles, grains, wall particles) for building the parts.
constexpr double kMaxBuildEntities = 4096;
// The validator refuses more than 2e8 particles per part (io/scenario/load.cpp, kMaxEntities,
// counted as region volume / spacing^D). This harness counts lattices over bounding boxes with
// one more point per axis (up to ~6.5x the validator's count in 3D) and wall particles within
// a factor 2, so an accepted scenario with a part of lattices / 8 + walls / 2 above 2e8 is a
// finding: the validator let through an allocation it exists to refuse.
constexpr double kMaxEntities = 2e8;

bool g_build = true;
long g_rejected = 0, g_accepted = 0, g_built = 0;

void print_stats() {
  std::fprintf(stderr,
               "fuzz_scenario: %ld rejected (InputError), %ld accepted, %ld of them built\n",
               g_rejected, g_accepted, g_built);
}

// "#set k=v" lines -> overrides.
std::vector<std::string> overrides_of(const std::string& text) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.rfind("#set ", 0) == 0) out.push_back(line.substr(5));
    pos = end + 1;
  }
  return out;
}

// Lattice points over the bounding box of a region at pitch s (as parts::region_lattice lays them).
double lattice_points(const RegionConfig& r, Real s, int dim) {
  double n = 1;
  for (int d = 0; d < dim; ++d) {
    const auto k = static_cast<std::size_t>(d);
    const double lo = r.type == RegionType::Box ? r.min_m[k] : r.center_m[k] - r.radius_m;
    const double hi = r.type == RegionType::Box ? r.max_m[k] : r.center_m[k] + r.radius_m;
    const double m = (hi - lo) / s;
    if (!std::isfinite(m)) return HUGE_VAL;
    n *= std::max(1.0, std::floor(m + 1e-9) + 1);
  }
  return n;
}

// Largest pitch of the particles of an SPH part: the part's, or a spacing zone's when that
// zone lays at least one particle (as sph::SphPart does: a zone owns its lattice points that
// lie in the part's region and in no later spacing zone). Zones of huge lattices are counted
// as laying particles (their lattice alone is reported as absurd).
template <int D>
Real largest_pitch(const PartConfig& p) {
  auto owner = [&](const crater::Vec<D>& x) {
    int k = -1;
    for (std::size_t z = 0; z < p.zones.size(); ++z)
      if (p.zones[z].spacing_m && region_contains<D>(p.zones[z].region, x)) k = static_cast<int>(z);
    return k;
  };
  Real pitch = p.spacing_m;
  for (std::size_t z = 0; z < p.zones.size(); ++z) {
    const auto& s = p.zones[z].spacing_m;
    if (!s || *s <= pitch) continue;
    if (lattice_points(p.zones[z].region, *s, D) > 1e5) {
      pitch = *s;
      continue;
    }
    for (const auto& x : region_lattice<D>(p.zones[z].region, *s))
      if (region_contains<D>(p.region, x) && owner(x) == static_cast<int>(z)) {
        pitch = *s;
        break;
      }
  }
  return pitch;
}

struct Estimate {
  double laid = 0;    // lattice points, zone lattices, grains placed by hand
  double walls = 0;   // dummy wall particles (no-slip SPH walls)
  double packed = 0;  // grains of random packings (bounded by dem::draw_radii, 5e7)
  double worst = 0;   // largest over the parts of laid / 8 + walls / 2 (see kMaxEntities)
  bool buildable = true;
};

// Generous upper bounds on the entities `crater check` would create, by kind.
Estimate estimate(const Config& c) {
  const int dim = c.dimension;
  Estimate e;
  for (const auto& p : c.parts) {
    const double laid0 = e.laid, walls0 = e.walls;
    if (p.is(Method::Sph)) {
      e.laid += lattice_points(p.region, p.spacing_m, dim);
      for (const auto& z : p.zones)
        if (z.spacing_m) e.laid += lattice_points(z.region, *z.spacing_m, dim);
      if (p.sph().wall_no_slip && !p.sph().walls.empty()) {
        // Layers: at least wall_layers, and enough for the support (2 h) of the coarsest
        // particle; a face is layers thick and spans the domain (plus the other faces' layers).
        const Real pitch = dim == 2 ? largest_pitch<2>(p) : largest_pitch<3>(p);
        const double layers = std::max<double>(
            p.sph().wall_layers, std::ceil(2 * p.sph().h_factor * pitch / p.spacing_m - 1e-9));
        for (const auto face : p.sph().walls) {
          const int axis = static_cast<int>(face) / 2;
          double n = layers;
          for (int d = 0; d < dim; ++d) {
            const auto k = static_cast<std::size_t>(d);
            if (d != axis)
              n *= (c.domain.max_m[k] - c.domain.min_m[k]) / p.spacing_m + 1 + 2 * layers;
          }
          e.walls += std::isfinite(n) ? n : HUGE_VAL;
        }
      }
    } else if (p.is(Method::Dem)) {
      if (p.packing().settle) e.buildable = false;  // a simulation, and a cache file on disk
      if (!p.dem().particles.empty()) {
        e.laid += static_cast<double>(p.dem().particles.size());
      } else if (p.packing().method != crater::dem::PackingMethod::Lattice) {
        // Grains of the smallest radius filling the region's bounding box.
        Real r = p.dem().radius_min_m;
        for (const Real dm : p.packing().sieve_diameter_m)
          r = std::min(r, 0.5 * dm);
        double vol = 1;
        for (int d = 0; d < dim; ++d) {
          const auto k = static_cast<std::size_t>(d);
          vol *= p.region.type == RegionType::Box ? p.region.max_m[k] - p.region.min_m[k]
                                                  : 2 * p.region.radius_m;
        }
        const double grain = dim == 2 ? M_PI * r * r : 4.0 / 3.0 * M_PI * r * r * r;
        e.packed += r > 0 ? vol / grain + 1 : HUGE_VAL;
      } else {
        e.laid += lattice_points(p.region, p.spacing_m, dim);
      }
    } else {
      e.buildable = false;  // a method this harness has not been taught to bound
    }
    const double part = (e.laid - laid0) / 8 + (e.walls - walls0) / 2;
    e.worst = std::max(e.worst, std::isfinite(part) ? part : HUGE_VAL);
  }
  if (!std::isfinite(e.laid)) e.laid = HUGE_VAL;
  if (!std::isfinite(e.walls)) e.walls = HUGE_VAL;
  if (!std::isfinite(e.packed)) e.packed = HUGE_VAL;
  return e;
}

[[noreturn]] void finding(const char* what) {
  std::fprintf(stderr, "fuzz_scenario: FINDING: %s\n", what);
  std::fflush(stderr);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  spdlog::set_level(spdlog::level::off);
  if (const char* b = std::getenv("CRATER_FUZZ_BUILD")) g_build = std::string(b) != "0";
  if (const char* st = std::getenv("CRATER_FUZZ_STATS"); st && std::string(st) != "0")
    std::atexit(print_stats);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const Config c = load_scenario_text(text, "fuzz.toml", overrides_of(text));
    ++g_accepted;
    const Estimate e = estimate(c);
    if (e.worst > kMaxEntities) {
      const std::string what = fmt::format(
          "the validator accepted a scenario of about {:.3g} lattice particles and {:.3g} wall "
          "particles: it must refuse it",
          e.laid, e.walls);
      finding(what.c_str());
    }
    if (g_build && e.buildable && e.laid + e.walls + e.packed <= kMaxBuildEntities) {
      ++g_built;
      const auto reports = crater::solver::check_scenario(c);
      // One row per part, and one more for the contacts when there are any.
      const std::size_t rows = c.parts.size() + (c.contacts.empty() ? 0 : 1);
      if (reports.size() != rows)
        finding("check_scenario: a report per part (+ contacts) expected");
    }
  } catch (const crater::InputError&) {
    ++g_rejected;  // expected: a bad file (exit 2)
  } catch (const std::exception& e) {
    const std::string what = std::string("escaped ") + typeid(e).name() + ": " + e.what();
    finding(what.c_str());
  } catch (...) {
    finding("escaped a non-std exception");
  }
  return 0;
}
