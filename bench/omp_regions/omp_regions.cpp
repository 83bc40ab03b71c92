/* Counts the OpenMP fork-joins and barriers a run makes, to see what a step costs in
 * synchronisation (docs/performance.md, "Barriers per step"). Loaded with LD_PRELOAD in front of
 * libgomp by bench/count_regions.sh; it forwards every call unchanged, so results are those of
 * the plain binary. At exit it writes its counts to the file named by CRATER_OMP_COUNTS.
 *
 * Counted: GOMP_parallel entries that fork a team (num_threads != 1) and those whose `if` clause
 * kept them on the calling thread (num_threads == 1: a loop below parallel_min), explicit
 * barriers (GOMP_barrier) and the barriers at the end of worksharing loops (GOMP_loop_end).
 * The join at the end of a forked region is a barrier too: regions forked + barriers is the
 * number of times the threads wait for each other. */
#include <dlfcn.h>

#include <cstdio>
#include <cstdlib>

namespace {
unsigned long long forked, kept_serial, barriers, loop_ends;
using parallel_fn = void (*)(void (*)(void*), void*, unsigned, unsigned);
using void_fn = void (*)();

__attribute__((destructor)) void report() {
  const char* path = std::getenv("CRATER_OMP_COUNTS");
  std::FILE* f = path ? std::fopen(path, "w") : stderr;
  if (!f) return;
  std::fprintf(f, "forked %llu\nkept_serial %llu\nbarrier %llu\nloop_end %llu\n", forked,
               kept_serial, barriers, loop_ends);
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
