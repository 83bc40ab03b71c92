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
constexpr const char* kMagic = "crater settled packing v2";

std::uint64_t checksum(std::string_view payload) {
  return fnv1a(payload);
}

// Appends the bytes of trivially copyable values.
template <class T>
void put(std::string& out, const std::vector<T>& v) {
  out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

// Reads n values from p, advancing it.
template <class T>
std::vector<T> take(const char*& p, std::size_t n) {
  std::vector<T> v(n);
  if (n > 0) std::memcpy(static_cast<void*>(v.data()), p, n * sizeof(T));
  p += n * sizeof(T);
  return v;
}
}  // namespace

template <int D>
void save_packing(const std::string& path, std::uint64_t key, const dem::SettledPacking<D>& s) {
  const auto& g = s.grains;
  const auto& h = s.contacts;
  std::string payload;
  payload.reserve(g.size() * (D + 1) * sizeof(double));
  for (const auto& q : g) {
    for (int d = 0; d < D; ++d)
      payload.append(reinterpret_cast<const char*>(&q.x[d]), sizeof(double));
    payload.append(reinterpret_cast<const char*>(&q.r), sizeof(double));
  }
  put(payload, h.partner);
  put(payload, h.xi);
  put(payload, h.roll);
  const std::string header =
      fmt::format("{} key={:016x} dim={} count={} slots={} roll={} checksum={:016x}\n", kMagic, key,
                  D, g.size(), h.slots, h.roll.empty() ? 0 : 1, checksum(payload));
  io::write_file_atomic(path, header + payload);
}

std::string read_packing_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

template <int D>
std::optional<dem::SettledPacking<D>> packing_from_bytes(std::string_view bytes,
                                                         std::uint64_t key) {
  const std::size_t eol = bytes.find('\n');
  if (eol == std::string_view::npos) return std::nullopt;
  const std::string header(bytes.substr(0, eol));
  const std::string_view payload = bytes.substr(eol + 1);
  unsigned long long k = 0, sum = 0;
  int dim = 0, slots = 0, roll = 0;
  std::size_t count = 0;
  const std::string expect =
      std::string(kMagic) + " key=%16llx dim=%d count=%zu slots=%d roll=%d checksum=%16llx";
  if (std::sscanf(header.c_str(), expect.c_str(), &k, &dim, &count, &slots, &roll, &sum) != 6)
    return std::nullopt;
  if (k != key || dim != D || count > (std::size_t{1} << 32) || slots < 0 || slots > 64)
    return std::nullopt;
  const std::size_t n = count * static_cast<std::size_t>(slots);
  const std::size_t expected = count * (D + 1) * sizeof(double) +
                               n * (sizeof(std::int64_t) + sizeof(Vec<D>)) +
                               (roll ? n * sizeof(dem::AngularVec<D>) : 0);
  if (payload.size() != expected || checksum(payload) != sum) return std::nullopt;
  dem::SettledPacking<D> s;
  s.grains.resize(count);
  const char* p = payload.data();
  for (auto& q : s.grains) {
    for (int d = 0; d < D; ++d, p += sizeof(double))
      std::memcpy(&q.x[d], p, sizeof(double));
    std::memcpy(&q.r, p, sizeof(double));
    p += sizeof(double);
    if (!q.x.allFinite() || !(q.r > 0)) return std::nullopt;
  }
  s.contacts.slots = slots;
  s.contacts.partner = take<std::int64_t>(p, n);
  s.contacts.xi = take<Vec<D>>(p, n);
  if (roll) s.contacts.roll = take<dem::AngularVec<D>>(p, n);
  for (const std::int64_t q : s.contacts.partner)
    if (q != dem::ContactHistory<D>::kNoPartner && q >= static_cast<std::int64_t>(count))
      return std::nullopt;
  return s;
}

#define CRATER_PACKING_CACHE(D)                                                                    \
  template void save_packing<D>(const std::string&, std::uint64_t, const dem::SettledPacking<D>&); \
  template std::optional<dem::SettledPacking<D>> packing_from_bytes<D>(std::string_view,           \
                                                                       std::uint64_t);
CRATER_PACKING_CACHE(2)
CRATER_PACKING_CACHE(3)
#undef CRATER_PACKING_CACHE

}  // namespace crater::solver
