// Memory a run will need, estimated from the scenario before any part is built, against the
// memory the machine has free: `crater check` prints it, and check and run refuse (InputError,
// exit 2) a scenario whose estimate exceeds output.memory_limit_fraction of what is available,
// naming each part, its estimated count and bytes, and the key that sets its resolution.
//
//   bytes = base + sum over parts of count x bytes_per_entity(method, dimension)
//               + no-slip wall particles x bytes_per_wall_particle(dimension)
//
// The coefficients are peak resident set sizes measured on this code (memory_estimate.cpp).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/scenario/config.hpp"

namespace crater::solver {

/// One part's share of the estimate.
struct PartMemory {
  std::string name;
  io::Method method{};
  Real count = 0;       // particles, grains or elements (PartConfig::estimated_count)
  Real wall_count = 0;  // no-slip wall particles (sph)
  double bytes = 0;
  std::string key;       // the key that sets the count, e.g. "parts.soil.spacing_m"
  SourceLocation where;  // its place in the input
};

struct MemoryEstimate {
  double base_bytes = 0;  // the program with no part
  std::vector<PartMemory> parts;
  double total_bytes() const;
};

/// Peak resident bytes per entity of a part (its method; for sph, whether h varies) in 2 or 3
/// dimensions.
double bytes_per_entity(const io::PartConfig& part, int dimension);

/// The estimate of a loaded scenario (counts from PartConfig::estimated_count).
MemoryEstimate estimate_memory(const io::Config& c);

/// Memory the process may still take [bytes], and where that figure comes from.
struct AvailableMemory {
  double bytes = 0;
  std::string source;  // "MemAvailable", "cgroup memory.max", "physical memory"
};

/// MemAvailable of /proc/meminfo (or the physical pages, sysconf), lowered to the room left
/// under the cgroup's memory.max when that is smaller.
AvailableMemory available_memory();

/// MemAvailable of a /proc/meminfo text [bytes], if it has the line.
std::optional<double> meminfo_available_bytes(const std::string& meminfo);

/// "1.23 GB", "45.6 MB", "812 kB" (decimal units).
std::string format_bytes(double bytes);

/// The line `crater check` prints: "memory: about 1.23 GB estimated (sph 0.40 GB, ...), 20.1 GB
/// available (MemAvailable); limit 0.8 x available".
std::string memory_line(const MemoryEstimate& m, const AvailableMemory& a, double fraction);

/// Throws InputErrors (exit 2), one per part that contributes, when the estimate exceeds
/// `fraction` x the available memory.
void require_memory(const MemoryEstimate& m, const AvailableMemory& a, double fraction);

/// The same for a loaded scenario, with the machine's available memory.
void require_memory(const io::Config& c);

/// What the program is doing, for the message of an allocation that fails anyway (main.cpp):
/// setting up (loading, building parts, checking: exit 2) or in the time loop (exit 3).
enum class Activity { Setup, TimeLoop };
void set_activity(Activity a);
Activity current_activity();

}  // namespace crater::solver
