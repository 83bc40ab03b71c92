// The settled-packing cache; see packing_cache.hpp.
#include "solver/packing_cache.hpp"

#include <fmt/format.h>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include "core/hash.hpp"
#include "io/output/atomic_file.hpp"

namespace crater::solver {

namespace {
constexpr const char* kMagic = "crater settled packing v1";

std::uint64_t checksum(const std::string& payload) {
  return fnv1a(payload);
}
}  // namespace

template <int D>
void save_packing(const std::string& path, std::uint64_t key, const std::vector<dem::Grain<D>>& g) {
  std::string payload;
  payload.resize(g.size() * (D + 1) * sizeof(double));
  char* p = payload.data();
  for (const auto& q : g) {
    for (int d = 0; d < D; ++d, p += sizeof(double))
      std::memcpy(p, &q.x[d], sizeof(double));
    std::memcpy(p, &q.r, sizeof(double));
    p += sizeof(double);
  }
  const std::string header = fmt::format("{} key={:016x} dim={} count={} checksum={:016x}\n",
                                         kMagic, key, D, g.size(), checksum(payload));
  io::write_file_atomic(path, header + payload);
}

template <int D>
std::optional<std::vector<dem::Grain<D>>> load_packing(const std::string& path, std::uint64_t key) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::string header;
  if (!std::getline(in, header)) return std::nullopt;
  unsigned long long k = 0, sum = 0;
  int dim = 0;
  std::size_t count = 0;
  const std::string expect = std::string(kMagic) + " key=%16llx dim=%d count=%zu checksum=%16llx";
  if (std::sscanf(header.c_str(), expect.c_str(), &k, &dim, &count, &sum) != 4) return std::nullopt;
  if (k != key || dim != D || count > (std::size_t{1} << 32)) return std::nullopt;
  std::string payload((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (payload.size() != count * (D + 1) * sizeof(double) || checksum(payload) != sum)
    return std::nullopt;
  std::vector<dem::Grain<D>> g(count);
  const char* p = payload.data();
  for (auto& q : g) {
    for (int d = 0; d < D; ++d, p += sizeof(double))
      std::memcpy(&q.x[d], p, sizeof(double));
    std::memcpy(&q.r, p, sizeof(double));
    p += sizeof(double);
    if (!q.x.allFinite() || !(q.r > 0)) return std::nullopt;
  }
  return g;
}

#define CRATER_PACKING_CACHE(D)                                                          \
  template void save_packing<D>(const std::string&, std::uint64_t,                       \
                                const std::vector<dem::Grain<D>>&);                      \
  template std::optional<std::vector<dem::Grain<D>>> load_packing<D>(const std::string&, \
                                                                     std::uint64_t);
CRATER_PACKING_CACHE(2)
CRATER_PACKING_CACHE(3)
#undef CRATER_PACKING_CACHE

}  // namespace crater::solver
