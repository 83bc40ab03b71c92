// Unit tests of the load-time size estimate (src/io/scenario/size_estimate.cpp) and the memory
// check (src/solver/memory_estimate.cpp): counts against closed forms, MemAvailable parsing,
// and the refusal naming each part that makes the estimate too big, with its key and line.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "io/scenario/load.hpp"
#include "io/scenario/size_estimate.hpp"
#include "io/scenario/validate.hpp"
#include "solver/memory_estimate.hpp"

namespace crater::solver {
namespace {

// A charge carved out of a box of sand: line 29 sets the charge's spacing, 36 the sand's.
const std::string kScenario = R"([scenario]
name = "unit-memory"
dimension = 2
end_time_s = 1.0e-5

[domain]
min_m = [0.0, 0.0]
max_m = [1.0, 2.0]

[[materials]]
name = "tnt"
model = "ideal_gas"
rho0_kg_m3 = 1.2
gamma = 1.4

[[materials]]
name = "sand"
model = "granular"
rho0_kg_m3 = 1920
shear_modulus_pa = 29e9
poisson_ratio = 0.2
friction = 0.5
restitution = 0.5

[[parts]]
name = "charge"
method = "sph"
material = "tnt"
spacing_m = 0.01
region = { type = "disk", center_m = [0.5, 0.5], radius_m = 0.1 }

[[parts]]
name = "sand"
method = "dem"
material = "sand"
spacing_m = 0.02
region = { type = "box", min_m = [0.0, 0.0], max_m = [1.0, 1.0] }
carve = ["charge"]
)";

io::Config load(const std::vector<std::string>& sets = {}) {
  return io::load_scenario_text(kScenario, "unit.toml", sets);
}

TEST(SizeEstimate, LatticeSitesLeaveTheCarvedRegionOut) {
  const io::Config c = load();
  const Real disk = std::numbers::pi * 0.1 * 0.1;
  EXPECT_NEAR(c.parts[0].estimated_count, disk / (0.01 * 0.01), 1e-9);
  EXPECT_NEAR(c.parts[1].estimated_count, (1.0 - disk) / (0.02 * 0.02), 1e-9);
  EXPECT_EQ(c.parts[1].resolution_key, "parts.sand.spacing_m");
  EXPECT_EQ(c.parts[1].resolution_where.line, 36);
}

TEST(SizeEstimate, RandomPackingCountsSolidVolumeOverMeanGrain) {
  const io::Config c =
      load({"parts.sand.packing.method=random", "parts.sand.packing.porosity=0.4",
            "parts.sand.dem.radius_min_m=0.002", "parts.sand.dem.radius_max_m=0.004"});
  const Real disk = std::numbers::pi * 0.1 * 0.1;
  const Real mean = std::numbers::pi * (4e-6 + 8e-6 + 16e-6) / 3;  // E[pi r^2], r in [2, 4] mm
  EXPECT_NEAR(c.parts[1].estimated_count, 0.6 * 1.0 / mean * (1 - disk), 1e-6);
  EXPECT_EQ(c.parts[1].resolution_key, "parts.sand.dem.radius_min_m");
}

TEST(SizeEstimate, MeanGrainVolumeOfEqualRadiiIsTheGrain) {
  EXPECT_NEAR(io::mean_grain_volume(0.5, 0.5, 2), std::numbers::pi * 0.25, 1e-15);
  EXPECT_NEAR(io::mean_grain_volume(0.5, 0.5, 3), 4.0 / 3.0 * std::numbers::pi * 0.125, 1e-15);
}

TEST(SizeEstimate, StructuredFemMeshCountsWholeElements) {
  io::PartConfig p;
  p.settings = io::FemConfig{};
  p.spacing_m = 0.02;
  p.region.min_m = {0.0, 0.0, 0.0};
  p.region.max_m = {1.0, 0.2, 0.1};
  io::Config c;
  c.dimension = 3;
  EXPECT_DOUBLE_EQ(io::fem_elements(c, p), 50.0 * 10.0 * 5.0);
}

TEST(MemoryEstimate, ParsesMemAvailable) {
  const std::string meminfo =
      "MemTotal:       24570000 kB\nMemFree:        1000 kB\nMemAvailable:   20000000 kB\n";
  EXPECT_DOUBLE_EQ(*meminfo_available_bytes(meminfo), 20000000.0 * 1024);
  EXPECT_FALSE(meminfo_available_bytes("MemTotal: 5 kB\n").has_value());
}

TEST(MemoryEstimate, FormatsDecimalUnits) {
  EXPECT_EQ(format_bytes(1.234e9), "1.23 GB");
  EXPECT_EQ(format_bytes(45.6e6), "45.6 MB");
  EXPECT_EQ(format_bytes(812e3), "812 kB");
}

TEST(MemoryEstimate, SumsBasePlusCountTimesBytesPerEntity) {
  const io::Config c = load();
  const MemoryEstimate m = estimate_memory(c);
  ASSERT_EQ(m.parts.size(), 2u);
  EXPECT_DOUBLE_EQ(m.parts[1].bytes, c.parts[1].estimated_count * bytes_per_entity(c.parts[1], 2));
  EXPECT_DOUBLE_EQ(m.total_bytes(), m.base_bytes + m.parts[0].bytes + m.parts[1].bytes);
  EXPECT_GT(bytes_per_entity(c.parts[0], 3), bytes_per_entity(c.parts[0], 2));
}

TEST(MemoryEstimate, RefusesNamingThePartsKeysAndLines) {
  const io::Config c = load({"parts.charge.spacing_m=0.005"});
  const MemoryEstimate m = estimate_memory(c);
  EXPECT_NO_THROW(require_memory(m, {1e12, "MemAvailable"}, 0.8));
  try {
    require_memory(m, {m.total_bytes(), "MemAvailable"}, 0.5);
    FAIL() << "expected a refusal";
  } catch (const io::InputErrors& e) {
    // Both parts make more than a tenth of the estimate.
    ASSERT_EQ(e.all().size(), 2u);
    EXPECT_EQ(e.all()[0].key(), "parts.charge.spacing_m");
    EXPECT_EQ(e.all()[0].where().file, "--set parts.charge.spacing_m=0.005");
    EXPECT_EQ(e.all()[1].key(), "parts.sand.spacing_m");
    const std::string what = e.all()[1].what();
    EXPECT_NE(what.find("unit.toml:36"), std::string::npos) << what;
    EXPECT_NE(what.find("grains"), std::string::npos) << what;
    EXPECT_NE(what.find("output.memory_limit_fraction = 0.5"), std::string::npos) << what;
  }
}

TEST(MemoryEstimate, ActivityTellsSetupFromTimeLoop) {
  set_activity(Activity::TimeLoop);
  EXPECT_EQ(current_activity(), Activity::TimeLoop);
  set_activity(Activity::Setup);
  EXPECT_EQ(current_activity(), Activity::Setup);
}

}  // namespace
}  // namespace crater::solver
