#include "solver/memory_estimate.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <sstream>

#include "io/scenario/validate.hpp"  // InputErrors

namespace crater::solver {
namespace {

// Peak resident set size per entity [bytes]: `/usr/bin/time -v crater run ...` ("Maximum
// resident set size") at three or four resolutions of one scenario per method and dimension
// (--set parts.<p>.spacing_m), the base subtracted, divided by the count, rounded up; on the
// development machine (2 cores, 24 GiB, Debian 12, GCC 12 Release build, 2 OpenMP threads,
// 2026-11-25). docs/performance.md "Memory estimate" has the commands and the figures.
//   sph: demo (2D) and tests/data/sph3d_small.toml (3D), 3e4-5e5 particles: 1010-1020 B (2D)
//        and 2670-2830 B (3D) over the first steps and with variable_h = false for whole runs;
//        with variable h the neighbour lists (built at the largest smoothing length) grow as the
//        charge expands: whole runs peak at 2690-3080 B (2D, demo, 3e4-6e4 particles; one run
//        of 1.3e5 reached 4800 B in a list's reallocation) and 5080 B (3D, 8e-5 s).
//   dem: tests/data/dem_bed_2d.toml (1e4-1.6e5 grains, lattice; random packing 1640 B) and a
//        3D box of grains (8e3-1.25e5): 1530-1640 B and 2530-2660 B, flat over 6000 steps.
//   fem: tests/data/fem_plate_2d.toml (1.6e4-2.6e5 elements) and a 3D plate (1.25e4-2.3e5):
//        1105-1120 B and 1630-1740 B per element.
//   sph no-slip wall particles: 90 B (2D), 101 B (3D).
// Known low: paper-20cm --level medium estimates 166 MB and holds 230 MB from t = 1.5 ms on
// (its charge's products expanding into the soil); its first 50 steps take 127 MB.
// The program and its libraries (demo at 80 particles): 7.4 MB until Open MPI's libraries were
// linked (loaded, not started: +2.3 MB, 2026-11-28).
constexpr double kBaseBytes = 9.7e6;

struct MethodBytes {
  double sph_fixed_h = 0, sph_variable_h = 0, dem = 0, fem = 0, sph_wall = 0;
};
constexpr MethodBytes kBytes2d{
    .sph_fixed_h = 1100, .sph_variable_h = 3000, .dem = 1650, .fem = 1150, .sph_wall = 120};
constexpr MethodBytes kBytes3d{
    .sph_fixed_h = 2900, .sph_variable_h = 5100, .dem = 2700, .fem = 1800, .sph_wall = 150};

std::atomic<int> g_activity{static_cast<int>(Activity::Setup)};

const char* entity_noun(io::Method method) {
  return method == io::Method::Sph   ? "particles"
         : method == io::Method::Dem ? "grains"
                                     : "elements";
}

std::string read_text(const char* path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Room under the cgroup (v2) limit: memory.max - memory.current, if there is a limit.
std::optional<double> cgroup_room_bytes() {
  const std::string max = read_text("/sys/fs/cgroup/memory.max");
  const std::string cur = read_text("/sys/fs/cgroup/memory.current");
  if (max.empty() || cur.empty() || max.rfind("max", 0) == 0) return std::nullopt;
  try {
    return std::max(0.0, std::stod(max) - std::stod(cur));
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::string part_message(const PartMemory& p, const MemoryEstimate& m, const AvailableMemory& a,
                         double fraction) {
  std::string walls;
  if (p.wall_count > 0) walls = fmt::format(" and {:.3g} no-slip wall particles", p.wall_count);
  return fmt::format(
      "part '{}' ({}): about {:.3g} {}{} need about {} of the {} estimated for the run, above "
      "the limit of {} (output.memory_limit_fraction = {} of {} available, {}); coarsen the "
      "resolution or free memory",
      p.name, io::method_name(p.method), p.count, entity_noun(p.method), walls,
      format_bytes(p.bytes), format_bytes(m.total_bytes()), format_bytes(fraction * a.bytes),
      fraction, format_bytes(a.bytes), a.source);
}

}  // namespace

double MemoryEstimate::total_bytes() const {
  double s = base_bytes;
  for (const auto& p : parts)
    s += p.bytes;
  return s;
}

double bytes_per_entity(const io::PartConfig& part, int dimension) {
  const MethodBytes& b = dimension == 3 ? kBytes3d : kBytes2d;
  if (part.is(io::Method::Sph)) return part.sph().variable_h ? b.sph_variable_h : b.sph_fixed_h;
  return part.is(io::Method::Dem) ? b.dem : b.fem;
}

MemoryEstimate estimate_memory(const io::Config& c) {
  MemoryEstimate m;
  m.base_bytes = kBaseBytes;
  const MethodBytes& b = c.dimension == 3 ? kBytes3d : kBytes2d;
  for (const auto& pc : c.parts) {
    PartMemory p{pc.name, pc.method(),       pc.estimated_count, pc.estimated_wall_count,
                 0,       pc.resolution_key, pc.resolution_where};
    p.bytes = p.count * bytes_per_entity(pc, c.dimension) + p.wall_count * b.sph_wall;
    m.parts.push_back(std::move(p));
  }
  return m;
}

std::optional<double> meminfo_available_bytes(const std::string& meminfo) {
  std::istringstream in(meminfo);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("MemAvailable:", 0) != 0) continue;
    std::istringstream fields(line.substr(13));
    double kib = 0;
    if (fields >> kib) return kib * 1024;
  }
  return std::nullopt;
}

AvailableMemory available_memory() {
  AvailableMemory a;
  if (const auto b = meminfo_available_bytes(read_text("/proc/meminfo"))) {
    a = {*b, "MemAvailable"};
  } else {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    a = {pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0,
         "physical memory"};
  }
  if (const auto room = cgroup_room_bytes(); room && *room < a.bytes)
    a = {*room, "cgroup memory.max"};
  return a;
}

std::string format_bytes(double bytes) {
  if (bytes >= 1e9) return fmt::format("{:.3g} GB", bytes / 1e9);
  if (bytes >= 1e6) return fmt::format("{:.3g} MB", bytes / 1e6);
  return fmt::format("{:.3g} kB", bytes / 1e3);
}

std::string memory_line(const MemoryEstimate& m, const AvailableMemory& a, double fraction) {
  std::string per;
  for (const io::Method method : {io::Method::Sph, io::Method::Dem, io::Method::Fem}) {
    double s = 0;
    for (const auto& p : m.parts)
      if (p.method == method) s += p.bytes;
    if (s > 0)
      per +=
          fmt::format("{}{} {}", per.empty() ? "" : ", ", io::method_name(method), format_bytes(s));
  }
  return fmt::format(
      "memory: about {} estimated ({}{}base {}), {} available ({}); limit {} x "
      "available",
      format_bytes(m.total_bytes()), per, per.empty() ? "" : ", ", format_bytes(m.base_bytes),
      format_bytes(a.bytes), a.source, fraction);
}

void require_memory(const MemoryEstimate& m, const AvailableMemory& a, double fraction) {
  if (m.total_bytes() <= fraction * a.bytes) return;
  // Every part that makes a tenth of the estimate or more (at least the largest one).
  double largest = 0;
  for (const auto& p : m.parts)
    largest = std::max(largest, p.bytes);
  std::vector<InputError> errors;
  for (const auto& p : m.parts)
    if (p.bytes > 0 && (p.bytes >= 0.1 * m.total_bytes() || p.bytes == largest))
      errors.emplace_back(p.where, p.key, part_message(p, m, a, fraction));
  if (errors.empty())
    errors.emplace_back(
        SourceLocation{}, "output.memory_limit_fraction",
        fmt::format("the run needs about {} (estimate), above {} x {} available "
                    "({})",
                    format_bytes(m.total_bytes()), fraction, format_bytes(a.bytes), a.source));
  throw io::InputErrors(std::move(errors));
}

void require_memory(const io::Config& c) {
  require_memory(estimate_memory(c), available_memory(), c.output.memory_limit_fraction);
}

void set_activity(Activity a) {
  g_activity.store(static_cast<int>(a));
}

Activity current_activity() {
  return static_cast<Activity>(g_activity.load());
}

}  // namespace crater::solver
