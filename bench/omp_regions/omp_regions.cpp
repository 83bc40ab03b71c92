/* Counts the OpenMP fork-joins and barriers a run makes, to see what a step costs in
 * synchronisation (docs/performance.md, "Barriers per step"). Loaded with LD_PRELOAD in front of
 * libgomp by bench/count_regions.sh; it forwards every call unchanged, so results are those of
 * the plain binary. At exit it writes its counts to the file named by CRATER_OMP_COUNTS.
 *
 * Counted: GOMP_parallel entries that fork a team (num_threads != 1) and those whose `if` clause
 * kept them on the calling thread (num_threads == 1: a loop below parallel_min), explicit
 * barriers (GOMP_barrier) and the barriers at the end of worksharing loops (GOMP_loop_end).
 * The join at the end of a forked region is a barrier too: regions forked + barriers is the
 * number of times the threads wait for each other.
 *
 * Per call site too: each region's outlined function (its address less its object's load
 * address, which `nm` of the binary names) with the regions it forked and those it kept serial,
 * as lines "site OFFSET OBJECT forked kept_serial". */
#include <dlfcn.h>

#include <cstdio>
#include <cstdlib>

namespace {
unsigned long long forked, kept_serial, barriers, loop_ends;

// Open addressing on the outlined function's address; a run has a few hundred sites. Only the
// thread that forks a region counts it (regions are not nested here).
struct Site {
  void (*fn)(void*);
  unsigned long long forked, kept_serial;
};
constexpr unsigned kSites = 4096;
Site sites[kSites];

void count_site(void (*fn)(void*), bool forks) {
  auto h = (reinterpret_cast<unsigned long>(fn) >> 4) % kSites;
  for (unsigned probe = 0; probe < kSites; ++probe, h = (h + 1) % kSites) {
    if (sites[h].fn == nullptr) sites[h].fn = fn;
    if (sites[h].fn != fn) continue;
    ++(forks ? sites[h].forked : sites[h].kept_serial);
    return;
  }
}
using parallel_fn = void (*)(void (*)(void*), void*, unsigned, unsigned);
using void_fn = void (*)();

__attribute__((destructor)) void report() {
  const char* path = std::getenv("CRATER_OMP_COUNTS");
  std::FILE* f = path ? std::fopen(path, "w") : stderr;
  if (!f) return;
  std::fprintf(f, "forked %llu\nkept_serial %llu\nbarrier %llu\nloop_end %llu\n", forked,
               kept_serial, barriers, loop_ends);
  for (const Site& site : sites) {
    if (!site.fn) continue;
    Dl_info info{};
    const bool known = dladdr(reinterpret_cast<void*>(site.fn), &info) && info.dli_fbase;
    const auto offset = reinterpret_cast<unsigned long>(site.fn) -
                        (known ? reinterpret_cast<unsigned long>(info.dli_fbase) : 0ul);
    std::fprintf(f, "site %#lx %s %llu %llu\n", offset,
                 known && info.dli_fname ? info.dli_fname : "?", site.forked, site.kept_serial);
  }
  if (f != stderr) std::fclose(f);
}
}  // namespace

extern "C" {

void GOMP_parallel(void (*fn)(void*), void* data, unsigned num_threads, unsigned flags) {
  static parallel_fn real;
  if (!real) real = reinterpret_cast<parallel_fn>(dlsym(RTLD_NEXT, "GOMP_parallel"));
  if (num_threads == 1)
    ++kept_serial;
  else
    ++forked;
  count_site(fn, num_threads != 1);
  real(fn, data, num_threads, flags);
}

void GOMP_barrier() {
  static void_fn real;
  if (!real) real = reinterpret_cast<void_fn>(dlsym(RTLD_NEXT, "GOMP_barrier"));
  __atomic_add_fetch(&barriers, 1, __ATOMIC_RELAXED);
  real();
}

void GOMP_loop_end() {
  static void_fn real;
  if (!real) real = reinterpret_cast<void_fn>(dlsym(RTLD_NEXT, "GOMP_loop_end"));
  __atomic_add_fetch(&loop_ends, 1, __ATOMIC_RELAXED);
  real();
}

}  // extern "C"
