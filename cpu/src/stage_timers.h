#pragma once
// Opt-in stage timers for the batched CPU strategies (issue 35: where a render's time goes on
// a host without perf). Built only with -DPATHBENCH_STAGE_TIMERS=ON (PB_STAGE_TIMERS=1); the
// default build compiles every PB_STAGE to nothing. Each scope reads the TSC (rdtsc, ~25
// cycles) on entry and exit and adds the difference to a per-thread accumulator; a thread's
// body (a pixel tile, a wavefront slice) flushes it into the process's totals once, and the
// render prints one table to stderr: per stage, the seconds summed over threads, their share
// of all threads' time in the render, calls and ns per call. Ticks become seconds by the TSC's
// rate measured over the render itself (steady_clock at both ends). Scopes are placed around
// calls that do >= one packet of work, never per path, so their own cost stays small (the
// profile build's wall time against the default build's says how small).
#include <cstdint>

#if defined(PB_STAGE_TIMERS) && PB_STAGE_TIMERS
#include <tbb/global_control.h>
#include <x86intrin.h>

#include <algorithm>

#include <atomic>
#include <chrono>
#include <new>
#include <cstdio>

namespace pb::cpu::stage {

enum Id : int { kThread, kCamera, kClosest, kClosestEmbree, kShade, kShadow, kShadowEmbree, kFinal, kFilm, kCount };
inline const char* const kNames[kCount] = {
    "rest: loops, routing", "camera: begin_paths",   "closest: tiny test", "closest: Embree (unsure)",
    "shade: path step",     "shadow: tiny test",     "shadow: Embree (unsure)", "final vertex",
    "film"};

struct Totals {
  std::atomic<uint64_t> ticks[kCount]{}, calls[kCount]{};
};
inline Totals totals;
struct Local {
  uint64_t ticks[kCount]{}, calls[kCount]{};
  int current = -1;    // the innermost open scope
  uint64_t since = 0;  // when it was entered or resumed
  void flush() {
    for (int i = 0; i < kCount; ++i) {
      totals.ticks[i].fetch_add(ticks[i], std::memory_order_relaxed);
      totals.calls[i].fetch_add(calls[i], std::memory_order_relaxed);
      ticks[i] = calls[i] = 0;
    }
  }
};
inline thread_local Local local;

// Exclusive times: a scope opened inside another pauses the outer one, so the stages add up
// to the threads' time, each tick counted once.
struct Scope {
  explicit Scope(Id id) : parent_(local.current) {
    const uint64_t now = __rdtsc();
    if (parent_ >= 0) local.ticks[parent_] += now - local.since;
    local.current = id;
    local.since = now;
    ++local.calls[id];
  }
  ~Scope() {
    const uint64_t now = __rdtsc();
    local.ticks[local.current] += now - local.since;
    local.current = parent_;
    local.since = now;
  }
  int parent_;
};
// A thread's body (its time outside every stage is kThread's) and the flush at its end.
struct ThreadScope {
  ThreadScope() { new (&s) Scope(kThread); }
  ~ThreadScope() {
    s.~Scope();  // a union member: destroyed here, once
    local.flush();
  }
  union {
    Scope s;
  };
};

// One render: reset at the start, print at the end.
struct Render {
  Render(const char* what, int threads) : what_(what), threads_(threads), c0_(std::chrono::steady_clock::now()), t0_(__rdtsc()) {
    for (int i = 0; i < kCount; ++i) totals.ticks[i] = totals.calls[i] = 0;
  }
  ~Render() {
    local.flush();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - c0_).count();
    const double hz = double(__rdtsc() - t0_) / wall;
    double all = 0.0;
    for (int i = 0; i < kCount; ++i) all += double(totals.ticks[i]) / hz;
    std::fprintf(stderr,
                 "stage timers: %s, render %.4f s wall x %d threads = %.4f thread-s; in the threads' bodies %.4f "
                 "(%.1f%%; the rest idle or scheduling); TSC %.3f GHz\n",
                 what_, wall, threads_, wall * threads_, all, 100.0 * all / (wall * threads_), hz * 1e-9);
    std::fprintf(stderr, "  %-28s %10s %7s %12s %9s\n", "stage (exclusive)", "thread-s", "share", "calls", "ns/call");
    for (int i = 0; i < kCount; ++i) {
      const double s = double(totals.ticks[i]) / hz;
      const uint64_t n = totals.calls[i];
      std::fprintf(stderr, "  %-28s %10.4f %6.1f%% %12llu %9.1f\n", kNames[i], s, all > 0 ? 100.0 * s / all : 0.0,
                   (unsigned long long)n, n ? 1e9 * s / double(n) : 0.0);
    }
  }
  const char* what_;
  int threads_;
  std::chrono::steady_clock::time_point c0_;
  uint64_t t0_;
};

}  // namespace pb::cpu::stage

#define PB_STAGE_CAT2(a, b) a##b
#define PB_STAGE_CAT(a, b) PB_STAGE_CAT2(a, b)
#define PB_STAGE(id) ::pb::cpu::stage::Scope PB_STAGE_CAT(pb_stage_, __LINE__)(::pb::cpu::stage::id)
#define PB_STAGE_THREAD() ::pb::cpu::stage::ThreadScope pb_stage_thread
#define PB_STAGE_RENDER(what, threads) \
  ::pb::cpu::stage::Render pb_stage_render(                                                                    \
      what, int(std::min<size_t>(size_t(threads),                                                              \
                                 tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism))))
#else
#define PB_STAGE(id) ((void)0)
#define PB_STAGE_THREAD() ((void)0)
#define PB_STAGE_RENDER(what, threads) ((void)0)
#endif
