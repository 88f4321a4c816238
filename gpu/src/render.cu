// The CUDA tracer: scene upload, the three strategies and the run report.
#include "pathbench/gpu/render.h"

#include <cuda_runtime.h>
#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#include "cuda_util.h"
#include "kernel_sync.h"
#include "pathbench/common/errors.h"
#include "pathbench/common/fingerprint.h"
#include "pathbench/common/path.h"
#include "pathbench/gpu/bvh.h"
#include "pathbench/gpu/bvh_build.h"

#ifndef PATHBENCH_CUDA_ARCHS
#define PATHBENCH_CUDA_ARCHS "?"
#endif

namespace pb::gpu {

namespace {

constexpr unsigned kFullMask = 0xFFFFFFFFu;
constexpr float kInf = std::numeric_limits<float>::infinity();

// ---------------------------------------------------------------------------------
// Film and counters on the device.

struct FilmDev {
  unsigned long long* sum;  // 3 per pixel, two's complement of Film's int64 sums
  uint32_t* count;
  double* sum_sq;           // null unless variance is kept
  double scale;
  double limit;             // a channel must stay strictly below this (Film::sample_limit)
};

__device__ __forceinline__ bool sample_acceptable(const Vec3f& L, double limit) {
  return isfinite(L.x) && isfinite(L.y) && isfinite(L.z) && double(fabsf(L.x)) < limit &&
         double(fabsf(L.y)) < limit && double(fabsf(L.z)) < limit;
}

struct Stats {
  unsigned long long camera, bounce, shadow, paths, discarded;
};

// ---------------------------------------------------------------------------------
// Probe kernel: tells whether this build's machine code runs on the device.
__global__ void k_probe() {}

// ---------------------------------------------------------------------------------
// pixel: one thread per pixel sample (grid-stride over all samples of the frame, a
// warp taking 32 consecutive samples), the whole path in registers. Samples of one
// pixel are summed in the warp (exact integer sums) before one atomic per pixel.

// The last-vertex shortcut of path.h (path_final_query: the emitters tested one by one
// plus one occlusion ray, instead of a closest-hit query) on the GPU: used after a
// bounce only, so a path's first ray is always traced by the closest-hit kernel (the
// wavefront's generate stage then stays a plain writer of camera rays). At depth 0 (a
// 0-bounce render) both GPU strategies take the closest hit instead: the same value.
template <class T>
__device__ __forceinline__ bool gpu_final_vertex(const SceneView& s, const PathConfig& c, const PathState<T>& st) {
  return st.depth > 0 && path_at_final_vertex(s, c, st);
}

// One path in registers, in scalar type T (the traversal finds the hit triangle in
// float either way; surface_hit recomputes the hit in T), with the watertight or the
// Moeller-Trumbore triangle test.
template <uint32_t Kinds, class T, bool kWatertight>
__device__ __forceinline__ Vec3f trace_path(const SceneView& s, const BvhView& bvh, const PathConfig& c,
                                            uint32_t pixel, uint32_t sample, uint32_t& n_bounce, uint32_t& n_shadow) {
  PathState<T> st;
  path_begin(s, c, pixel, sample, st);
  ShadowQuery<T> q;
  auto occlusion_test = [&](const ShadowQuery<T>& query) {  // query: q, filled just before
    ++n_shadow;
    if (!occluded<kWatertight>(bvh, Vec3f(query.ray.o), Vec3f(query.ray.d), 1.0f)) shadow_unoccluded(st, query);
  };
  for (;;) {
    if (gpu_final_vertex(s, c, st)) {  // only emitted light can still count
      if (path_final_query<Kinds>(s, c, st, q)) occlusion_test(q);
      break;
    }
    if (st.depth > 0) ++n_bounce;  // the camera ray is counted per path
    float t;
    const uint32_t prim = intersect_closest<kWatertight>(bvh, Vec3f(st.ray.o), Vec3f(st.ray.d), kInf, t);
    if (prim == kNoHit) break;
    bool wants_shadow;
    const PathEvent ev = path_hit<Kinds>(s, c, st, surface_hit(s, prim, st.ray), q, wants_shadow);
    if (wants_shadow) occlusion_test(q);
    if (ev == PathEvent::Done) break;
  }
  return Vec3f(st.L);
}

template <class T> __device__ __forceinline__ T shfl_down(T v, int off) { return __shfl_down_sync(kFullMask, v, off); }

__device__ void block_stats_add(Stats* stats, uint32_t bounce, uint32_t shadow, uint32_t paths, uint32_t discarded) {
  __shared__ unsigned long long acc[4];
  if (threadIdx.x < 4) acc[threadIdx.x] = 0;
  __syncthreads();
  bounce = __reduce_add_sync(kFullMask, bounce);
  shadow = __reduce_add_sync(kFullMask, shadow);
  paths = __reduce_add_sync(kFullMask, paths);
  discarded = __reduce_add_sync(kFullMask, discarded);
  if ((threadIdx.x & 31) == 0) {
    atomicAdd(&acc[0], bounce);
    atomicAdd(&acc[1], shadow);
    atomicAdd(&acc[2], paths);
    atomicAdd(&acc[3], discarded);
  }
  __syncthreads();
  if (threadIdx.x == 0) {
    atomicAdd(&stats->bounce, acc[0]);
    atomicAdd(&stats->shadow, acc[1]);
    atomicAdd(&stats->paths, acc[2]);
    atomicAdd(&stats->camera, acc[2]);
    atomicAdd(&stats->discarded, acc[3]);
  }
}

// Film add for a whole warp (all 32 lanes call it, convergent): samples of the same
// pixel in consecutive lanes are summed first (exact integer sums), then one atomic per
// pixel and channel. Strategies that hand out consecutive samples of a pixel to
// neighbouring lanes thus need ~1/32 of the atomics, and no lane of a warp waits on
// 32 same-address atomics.
template <bool kVariance>
__device__ __forceinline__ void film_add_warp(const FilmDev& film, bool add, uint32_t pixel, const Vec3f& L,
                                              unsigned long long* discarded) {
  const uint32_t lane = threadIdx.x & 31;
  const bool ok = add && sample_acceptable(L, film.limit);
  if (add && !ok) atomicAdd(discarded, 1ull);
  const uint32_t key = ok ? pixel : 0xFFFFFFFFu;
  long long q0 = ok ? quantize_radiance(L.x, film.scale) : 0;
  long long q1 = ok ? quantize_radiance(L.y, film.scale) : 0;
  long long q2 = ok ? quantize_radiance(L.z, film.scale) : 0;
  uint32_t cnt = ok ? 1u : 0u;
  double s0 = 0, s1 = 0, s2 = 0;
  if (kVariance && ok) {
    s0 = double(L.x) * double(L.x);
    s1 = double(L.y) * double(L.y);
    s2 = double(L.z) * double(L.z);
  }
  // Segmented sum over runs of equal keys in consecutive lanes (Hillis-Steele: after
  // the step with offset `off`, a lane holds the sum of [lane, lane + 2 off) within
  // its run). Runs are told apart by the lane that starts them, not by the key: one
  // pixel may have several runs in a warp.
  const uint32_t key_prev = __shfl_up_sync(kFullMask, key, 1);
  const uint32_t heads = __ballot_sync(kFullMask, lane == 0 || key_prev != key);
  const uint32_t run = 31u - uint32_t(__clz(heads & (0xFFFFFFFFu >> (31u - lane))));  // latest head <= lane
#pragma unroll
  for (int off = 1; off < 32; off <<= 1) {
    const uint32_t r2 = __shfl_down_sync(kFullMask, run, off);
    const long long a0 = __shfl_down_sync(kFullMask, q0, off), a1 = __shfl_down_sync(kFullMask, q1, off),
                    a2 = __shfl_down_sync(kFullMask, q2, off);
    const uint32_t c2 = __shfl_down_sync(kFullMask, cnt, off);
    double b0 = 0, b1 = 0, b2 = 0;
    if (kVariance) {
      b0 = __shfl_down_sync(kFullMask, s0, off);
      b1 = __shfl_down_sync(kFullMask, s1, off);
      b2 = __shfl_down_sync(kFullMask, s2, off);
    }
    if (lane + off < 32 && r2 == run) {
      q0 += a0; q1 += a1; q2 += a2;
      cnt += c2;
      if (kVariance) { s0 += b0; s1 += b1; s2 += b2; }
    }
  }
  if (key != 0xFFFFFFFFu && run == lane) {
    unsigned long long* sum = film.sum + size_t(key) * 3;
    atomicAdd(sum + 0, static_cast<unsigned long long>(q0));
    atomicAdd(sum + 1, static_cast<unsigned long long>(q1));
    atomicAdd(sum + 2, static_cast<unsigned long long>(q2));
    atomicAdd(film.count + key, cnt);
    if (kVariance) {
      double* sq = film.sum_sq + size_t(key) * 3;
      atomicAdd(sq + 0, s0);
      atomicAdd(sq + 1, s1);
      atomicAdd(sq + 2, s2);
    }
  }
}

template <bool kVariance, uint32_t Kinds, class T, bool kWatertight>
__global__ void __launch_bounds__(256) k_pixel(SceneView s, BvhView bvh, PathConfig c, uint32_t spp, uint64_t total,
                                               FilmDev film, Stats* stats) {
  kernel_prologue();
  const uint32_t lane = threadIdx.x & 31;
  const uint64_t warp = (uint64_t(blockIdx.x) * blockDim.x + threadIdx.x) >> 5;
  const uint64_t warps = (uint64_t(gridDim.x) * blockDim.x) >> 5;
  uint32_t n_bounce = 0, n_shadow = 0, n_paths = 0, n_discarded = 0;
  for (uint64_t base = warp * 32; base < total; base += warps * 32) {
    const uint64_t g = base + lane;
    const bool valid = g < total;
    const uint32_t pixel = valid ? uint32_t(g / spp) : 0xFFFFFFFFu;
    Vec3f L{0.0f, 0.0f, 0.0f};
    if (valid) {
      L = trace_path<Kinds, T, kWatertight>(s, bvh, c, pixel, uint32_t(g % spp), n_bounce, n_shadow);
      ++n_paths;
    }
    film_add_warp<kVariance>(film, valid, pixel, L, &stats->discarded);
  }
  block_stats_add(stats, n_bounce, n_shadow, n_paths, n_discarded);
}

// ---------------------------------------------------------------------------------
// wavefront and paper-queue: a pool of `capacity` paths in flight as structure of
// arrays, stage kernels linked by queues. Paths that continue are compacted into the
// other of two state buffers (warp-aggregated atomic append), new samples are appended
// after them, so every stage reads its paths contiguously. Each stage kernel loops over
// a count it reads on the device: the host never waits between stages.

struct PathSoA {
  float4* o;        // ray origin, bsdf_pdf
  float4* d;        // ray direction, pixel (bits)
  float4* beta;     // throughput, depth (bits)
  float4* L;        // radiance so far, sample (bits)
};

// Shadow rays of one iteration: a light-sampling ray, or the last vertex's emitter
// query (path_final_query), or both from the same origin (a "pair"). `target`: index
// of the continuing path in the next buffer, or kShadowDone | pixel for a path that
// ended (its radiance is in L; L.w != 0 marks a pair, whose second ray is d2/c2).
struct ShadowSoA {
  float4* o;        // origin, contribution.x
  float4* d;        // direction (unnormalised, to the light point), contribution.y
  float2* ct;       // contribution.z, target (bits)
  float4* L;        // radiance of a finished path, pair flag (written and read only for those)
  float4* d2;       // a pair's second ray: direction, contribution.x
  float2* c2;       // contribution.y, .z
};
constexpr uint32_t kShadowDone = 0x80000000u;  // pixels < 2^31 (RenderSettings::validate)

struct WaveCounters {
  uint32_t n_cur;      // paths to trace this iteration
  uint32_t n_next;     // paths continued into the next buffer
  uint32_t n_shadow;   // shadow rays queued this iteration
  uint32_t gen_count, gen_dst;
  uint32_t live;       // == n_cur after scheduling; 0: the frame is done
  unsigned long long next_sample, gen_base;
  Stats stats;
};

__device__ __forceinline__ uint32_t grid_thread() { return blockIdx.x * blockDim.x + threadIdx.x; }
__device__ __forceinline__ uint32_t grid_threads() { return gridDim.x * blockDim.x; }

// Warp-aggregated append: one atomic per warp.
__device__ __forceinline__ uint32_t queue_push(uint32_t* counter) {
  const uint32_t mask = __activemask();
  const uint32_t lane = threadIdx.x & 31;
  const int leader = __ffs(mask) - 1;
  uint32_t base = 0;
  if (int(lane) == leader) base = atomicAdd(counter, uint32_t(__popc(mask)));
  base = __shfl_sync(mask, base, leader);
  return base + uint32_t(__popc(mask & ((1u << lane) - 1u)));
}

__device__ __forceinline__ PathState<float> load_path(const PathSoA& p, uint32_t i) {
  const float4 o = p.o[i], d = p.d[i], b = p.beta[i], L = p.L[i];
  PathState<float> st;
  st.ray.o = {o.x, o.y, o.z};
  st.bsdf_pdf = o.w;
  st.ray.d = {d.x, d.y, d.z};
  st.pixel = __float_as_uint(d.w);
  st.beta = {b.x, b.y, b.z};
  st.depth = __float_as_uint(b.w);
  st.L = {L.x, L.y, L.z};
  st.sample = __float_as_uint(L.w);
  return st;
}

__device__ __forceinline__ void store_path(const PathSoA& p, uint32_t i, const PathState<float>& st) {
  p.o[i] = make_float4(st.ray.o.x, st.ray.o.y, st.ray.o.z, st.bsdf_pdf);
  p.d[i] = make_float4(st.ray.d.x, st.ray.d.y, st.ray.d.z, __uint_as_float(st.pixel));
  p.beta[i] = make_float4(st.beta.x, st.beta.y, st.beta.z, __uint_as_float(st.depth));
  p.L[i] = make_float4(st.L.x, st.L.y, st.L.z, __uint_as_float(st.sample));
}

// One thread: books the last iteration and plans this one's refill.
__global__ void k_wf_schedule(WaveCounters* ctr, unsigned long long total, uint32_t capacity) {
  kernel_prologue();
  if (grid_thread() != 0) return;
  WaveCounters& c = *ctr;
  const uint32_t cont = c.n_next;  // paths that continued from the last shade
  c.stats.bounce += cont;
  c.stats.shadow += c.n_shadow;
  const unsigned long long remaining = total - c.next_sample;
  const uint32_t room = capacity - cont;
  const uint32_t n = uint32_t(remaining < room ? remaining : room);
  c.gen_count = n;
  c.gen_dst = cont;
  c.gen_base = c.next_sample;
  c.next_sample += n;
  c.stats.camera += n;
  c.n_cur = cont + n;
  c.n_next = 0;
  c.n_shadow = 0;
  c.live = c.n_cur;
}

// New samples after the continuing paths; a warp takes consecutive samples of a pixel,
// as the pixel strategy does (coherent camera rays).
__global__ void __launch_bounds__(256, 6) k_wf_generate(SceneView s, PathConfig c, PathSoA cur, const WaveCounters* ctr, uint32_t spp) {
  kernel_prologue();
  const uint32_t n = ctr->gen_count, dst = ctr->gen_dst;
  const unsigned long long base = ctr->gen_base;
  for (uint32_t i = grid_thread(); i < n; i += grid_threads()) {
    const unsigned long long g = base + i;
    PathState<float> st;
    path_begin(s, c, uint32_t(g / spp), uint32_t(g % spp), st);
    store_path(cur, dst + i, st);
  }
}

__global__ void __launch_bounds__(256, 5) k_wf_intersect(BvhView bvh, PathSoA cur, uint32_t* prim, const WaveCounters* ctr) {
  kernel_prologue();
  const uint32_t n = ctr->n_cur;
  for (uint32_t i = grid_thread(); i < n; i += grid_threads()) {
    const float4 o = cur.o[i], d = cur.d[i];
    float t;
    prim[i] = intersect_closest(bvh, {o.x, o.y, o.z}, {d.x, d.y, d.z}, kInf, t);
  }
}

__device__ __forceinline__ void push_shadow(const ShadowSoA& sh, uint32_t k, const ShadowQuery<float>& q, uint32_t target) {
  sh.o[k] = make_float4(q.ray.o.x, q.ray.o.y, q.ray.o.z, q.contribution.x);
  sh.d[k] = make_float4(q.ray.d.x, q.ray.d.y, q.ray.d.z, q.contribution.y);
  sh.ct[k] = make_float2(q.contribution.z, __uint_as_float(target));
}

template <bool kVariance, uint32_t Kinds>
__global__ void __launch_bounds__(256, 3) k_wf_shade(SceneView s, PathConfig c, PathSoA cur, PathSoA next,
                                                     const uint32_t* prim, ShadowSoA sh, WaveCounters* ctr, FilmDev film) {
  kernel_prologue();
  const uint32_t n = ctr->n_cur;
  const uint32_t lane = threadIdx.x & 31, warp = grid_thread() >> 5, warps = grid_threads() >> 5;
  for (uint32_t base = warp * 32; base < n; base += warps * 32) {  // warp-uniform: film_add_warp
    const uint32_t i = base + lane;
    bool add = false, pair = false;
    uint32_t pixel = 0;
    Vec3f L_add{0.0f, 0.0f, 0.0f};
    if (i < n) {
      PathState<float> st = load_path(cur, i);
      const uint32_t h = prim[i];
      pixel = st.pixel;
      if (h == kNoHit) {
        add = true;
        L_add = st.L;
      } else {
        ShadowQuery<float> q, fq;
        bool wants_shadow;
        PathEvent ev = path_hit<Kinds>(s, c, st, surface_hit(s, h, st.ray), q, wants_shadow);
        // The next vertex would be the last: answer it here (trace_path does the same
        // at the top of its loop), so the path never goes through intersect + shade again.
        bool final_ray = false;
        if (ev == PathEvent::Continue && gpu_final_vertex(s, c, st)) {
          final_ray = path_final_query<Kinds>(s, c, st, fq);
          ev = PathEvent::Done;
        }
        uint32_t target = kShadowDone | st.pixel;
        if (ev == PathEvent::Continue) {
          const uint32_t j = queue_push(&ctr->n_next);
          store_path(next, j, st);
          target = j;
        }
        if (wants_shadow || final_ray) {
          // Light-sampling ray first (shadow_unoccluded's order in trace_path); both
          // rays of a pair leave from the same origin (the offset hit point).
          const uint32_t k = queue_push(&ctr->n_shadow);
          push_shadow(sh, k, wants_shadow ? q : fq, target);
          pair = wants_shadow && final_ray;
          if (pair) {
            sh.d2[k] = make_float4(fq.ray.d.x, fq.ray.d.y, fq.ray.d.z, fq.contribution.x);
            sh.c2[k] = make_float2(fq.contribution.y, fq.contribution.z);
          }
          if (target & kShadowDone) sh.L[k] = make_float4(st.L.x, st.L.y, st.L.z, pair ? 1.0f : 0.0f);
        } else if (ev == PathEvent::Done) {
          add = true;
          L_add = st.L;
        }
      }
    }
    film_add_warp<kVariance>(film, add, pixel, L_add, &ctr->stats.discarded);
    const uint32_t pairs = __reduce_add_sync(kFullMask, pair ? 1u : 0u);  // second rays of pairs
    if (lane == 0 && pairs) atomicAdd(&ctr->stats.shadow, static_cast<unsigned long long>(pairs));
  }
}

template <bool kVariance>
__global__ void __launch_bounds__(256, 5) k_wf_shadow(BvhView bvh, ShadowSoA sh, PathSoA next, WaveCounters* ctr,
                                                      FilmDev film) {
  kernel_prologue();
  const uint32_t n = ctr->n_shadow;
  const uint32_t lane = threadIdx.x & 31, warp = grid_thread() >> 5, warps = grid_threads() >> 5;
  for (uint32_t base = warp * 32; base < n; base += warps * 32) {  // warp-uniform: film_add_warp
    const uint32_t i = base + lane;
    bool add = false;
    uint32_t pixel = 0;
    Vec3f L{0.0f, 0.0f, 0.0f};
    if (i < n) {
      const float4 o = sh.o[i], d = sh.d[i];
      const float2 ct = sh.ct[i];
      const uint32_t target = __float_as_uint(ct.y);
      const Vec3f origin{o.x, o.y, o.z};
      const bool visible = !occluded(bvh, origin, {d.x, d.y, d.z}, 1.0f);
      if (target & kShadowDone) {
        const float4 l = sh.L[i];
        L = {l.x, l.y, l.z};
        if (visible) L = L + Vec3f{o.w, d.w, ct.x};  // shadow_unoccluded: L += contribution
        if (l.w != 0.0f) {                             // a pair: the last vertex's emitter query
          const float4 d2 = sh.d2[i];
          const float2 c2 = sh.c2[i];
          if (!occluded(bvh, origin, {d2.x, d2.y, d2.z}, 1.0f)) L = L + Vec3f{d2.w, c2.x, c2.y};
        }
        add = true;
        pixel = target & ~kShadowDone;
      } else if (visible) {
        float4 Lt = next.L[target];
        Lt.x = Lt.x + o.w;
        Lt.y = Lt.y + d.w;
        Lt.z = Lt.z + ct.x;
        next.L[target] = Lt;
      }
    }
    film_add_warp<kVariance>(film, add, pixel, L, &ctr->stats.discarded);
  }
}

// ---------------------------------------------------------------------------------
// Traversal for tests.
__global__ void k_trace(BvhView bvh, const TraceQuery* rays, TraceResult* out, uint32_t n, bool any_hit) {
  kernel_prologue();
  for (uint32_t i = grid_thread(); i < n; i += grid_threads()) {
    const TraceQuery r = rays[i];
    float t = r.t_max;
    uint32_t prim = any_hit ? traverse<true>(bvh, r.o, r.d, r.t_max, t) : traverse<false>(bvh, r.o, r.d, r.t_max, t);
    out[i] = {prim, t};
  }
}

// The kernel driver's version ("580.159.04"), from /proc on Linux; empty elsewhere.
std::string kernel_driver_version() {
  std::FILE* f = std::fopen("/proc/driver/nvidia/version", "r");
  if (!f) return {};
  char line[512] = {0};
  std::string v;
  if (std::fgets(line, sizeof line, f)) {
    const std::string l = line;
    // "NVRM version: NVIDIA UNIX [Open ]Kernel Module [for x86_64]  580.159.04  ...": the
    // first token after "Kernel Module" that starts with a digit and holds a dot.
    const size_t k = l.find("Kernel Module");
    size_t pos = k == std::string::npos ? 0 : k;
    while (pos < l.size()) {
      const size_t a = l.find_first_not_of(" \t\n", pos);
      if (a == std::string::npos) break;
      const size_t b = l.find_first_of(" \t\n", a);
      const std::string tok = l.substr(a, b == std::string::npos ? std::string::npos : b - a);
      if (std::isdigit(static_cast<unsigned char>(tok[0])) && tok.find('.') != std::string::npos) {
        v = tok;
        break;
      }
      if (b == std::string::npos) break;
      pos = b;
    }
  }
  std::fclose(f);
  return v;
}

void ensure_device() {
  std::string why;
  if (!device_available(&why)) throw InputError(fmt::format("--device gpu: {}", why));
}

struct ScopedStream {
  cudaStream_t s = nullptr;
  ScopedStream() { PB_CUDA_CHECK(cudaStreamCreateWithFlags(&s, cudaStreamNonBlocking)); }
  ~ScopedStream() { if (s) cudaStreamDestroy(s); }
};
struct ScopedEvent {
  cudaEvent_t e = nullptr;
  ScopedEvent() { PB_CUDA_CHECK(cudaEventCreate(&e)); }
  ~ScopedEvent() { if (e) cudaEventDestroy(e); }
};

}  // namespace

// -----------------------------------------------------------------------------------
// Device facts.

bool device_available(std::string* why_not) {
  int n = 0;
  cudaError_t e = cudaGetDeviceCount(&n);
  if (e != cudaSuccess || n == 0) {
    (void)cudaGetLastError();
    if (why_not)
      *why_not = e != cudaSuccess ? fmt::format("no usable CUDA device ({})", cudaGetErrorString(e))
                                  : std::string("no CUDA device found");
    return false;
  }
  cudaFuncAttributes attr;
  e = cudaFuncGetAttributes(&attr, k_probe);
  if (e != cudaSuccess) {
    (void)cudaGetLastError();
    cudaDeviceProp prop{};
    cudaGetDeviceProperties(&prop, 0);
    if (why_not)
      *why_not = fmt::format("this build's kernels (CUDA architectures {}) cannot run on {} (sm_{}{}): {}; rebuild "
                             "with -DCMAKE_CUDA_ARCHITECTURES={}{}",
                             PATHBENCH_CUDA_ARCHS, prop.name, prop.major, prop.minor, cudaGetErrorString(e),
                             prop.major, prop.minor);
    return false;
  }
  return true;
}

DeviceInfo device_info() {
  ensure_device();
  DeviceInfo info;
  PB_CUDA_CHECK(cudaGetDevice(&info.device));
  cudaDeviceProp prop{};
  PB_CUDA_CHECK(cudaGetDeviceProperties(&prop, info.device));
  info.name = prop.name;
  info.compute_major = prop.major;
  info.compute_minor = prop.minor;
  info.multiprocessors = prop.multiProcessorCount;
  info.total_memory = prop.totalGlobalMem;
  PB_CUDA_CHECK(cudaDriverGetVersion(&info.driver_version));
  PB_CUDA_CHECK(cudaRuntimeGetVersion(&info.runtime_version));
  info.slug = pb::slugify(info.name, "unknown-gpu");
  return info;
}

uint64_t default_paths_in_flight() {
  const DeviceInfo info = device_info();
  int threads_per_sm = 0;
  PB_CUDA_CHECK(cudaDeviceGetAttribute(&threads_per_sm, cudaDevAttrMaxThreadsPerMultiProcessor, info.device));
  // Five full waves of threads: enough paths for every stage to fill the device
  // (about 1.35 million on an H100); at 192 bytes a path (with light sampling) the pool
  // takes ~260 MB, which leaves room for a 2048x2048 film under 512 MB.
  return uint64_t(info.multiprocessors) * uint64_t(threads_per_sm) * 5;
}

// -----------------------------------------------------------------------------------
// The scene on the device.

struct GpuScene::Impl {
  DeviceBuffer<Vec3f> positions;
  DeviceBuffer<Triangle> triangles;
  DeviceBuffer<uint32_t> material_ids;
  DeviceBuffer<Material> materials;
  DeviceBuffer<uint32_t> emitters;
  DeviceBuffer<float> emitter_cdf;
  DeviceBuffer<BvhNode> nodes;
  DeviceBuffer<BvhTriangle> tris;
  SceneView view{};
  BvhView bvh{};
  uint64_t bytes = 0;
  uint32_t bvh_depth = 0, bvh_leaves = 0;
  double bvh_sah = 0, bvh_build_seconds = 0, upload_seconds = 0;
};

GpuScene::GpuScene(const Scene& scene) : impl_(std::make_unique<Impl>()) {
  ensure_device();
  Impl& m = *impl_;
  const BvhHost bvh = build_bvh(scene);
  const auto t0 = std::chrono::steady_clock::now();
  const char* lower = "the scene's size (fewer triangles)";
  m.positions.assign(scene.positions, "scene vertices", lower);
  m.triangles.assign(scene.triangles, "scene triangles", lower);
  m.material_ids.assign(scene.material_ids, "material ids", lower);
  m.materials.assign(scene.materials, "materials", lower);
  m.emitters.assign(scene.emitters, "emitter table", lower);
  m.emitter_cdf.assign(scene.emitter_cdf, "emitter table", lower);
  m.nodes.assign(bvh.nodes, "BVH nodes", lower);
  m.tris.assign(bvh.tris, "BVH triangles", lower);
  m.view = scene.view();
  m.view.positions = m.positions.get();
  m.view.triangles = m.triangles.get();
  m.view.material_ids = m.material_ids.get();
  m.view.materials = m.materials.get();
  m.view.emitters = m.emitters.get();
  m.view.emitter_cdf = m.emitter_cdf.get();
  m.bvh = {m.nodes.get(), m.tris.get(), uint32_t(bvh.nodes.size()), uint32_t(bvh.tris.size())};
  m.bytes = m.positions.bytes() + m.triangles.bytes() + m.material_ids.bytes() + m.materials.bytes() +
            m.emitters.bytes() + m.emitter_cdf.bytes() + m.nodes.bytes() + m.tris.bytes();
  m.bvh_depth = bvh.depth;
  m.bvh_leaves = bvh.leaves;
  m.bvh_sah = bvh.sah_cost;
  m.bvh_build_seconds = bvh.build_seconds;
  m.upload_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

GpuScene::~GpuScene() = default;

// -----------------------------------------------------------------------------------
// Rendering.

namespace {

struct FilmBuffers {
  DeviceBuffer<unsigned long long> sum;
  DeviceBuffer<uint32_t> count;
  DeviceBuffer<double> sum_sq;
  FilmDev view{};
  void allocate(const Film& film, uint64_t pixels) {
    const char* lower = "--width/--height";
    sum.allocate(pixels * 3, "the film", lower);
    count.allocate(pixels, "the film", lower);
    if (film.has_variance()) sum_sq.allocate(pixels * 3, "the film's variance (--variance-out)", lower);
    view = {sum.get(), count.get(), sum_sq.get(), film.scale(), film.sample_limit()};
  }
  void clear(cudaStream_t s) {
    PB_CUDA_CHECK(cudaMemsetAsync(sum.get(), 0, sum.bytes(), s));
    PB_CUDA_CHECK(cudaMemsetAsync(count.get(), 0, count.bytes(), s));
    if (sum_sq.get()) PB_CUDA_CHECK(cudaMemsetAsync(sum_sq.get(), 0, sum_sq.bytes(), s));
  }
  uint64_t bytes() const { return sum.bytes() + count.bytes() + sum_sq.bytes(); }
};

struct FrameResult {
  Stats stats{};
  uint64_t state_bytes_per_path = 0, queue_bytes_per_path = 0, paths_in_flight = 0, pool_bytes = 0;
  uint64_t iterations = 0;
};

// Which shadow records a frame needs: light-sampling rays, the last vertex's emitter
// queries (bounded paths, few emitters: path_at_final_vertex), and pairs of both.
struct ShadowUse {
  bool records = false;
  bool pairs = false;
  static ShadowUse of(const Scene& scene, const RenderSettings& settings) {
    const bool lights = !scene.emitters.empty();
    const bool nee = lights && settings.sampling == Sampling::Nee;
    const bool final_queries = lights && settings.max_bounces > 0 && scene.emitters.size() <= kMaxEmittersForFinalQuery;
    return {nee || final_queries, nee && final_queries};
  }
};

// Path pool shared by wavefront and paper-queue.
class PathPool {
 public:
  PathPool(uint64_t capacity, ShadowUse shadows, const char* what, const char* lower)
      : capacity_(capacity), shadows_(shadows) {
    for (auto& b : buf_) b.allocate(capacity, what, lower);
    prim_.allocate(capacity, what, lower);
    if (shadows.records) {
      sh_o_.allocate(capacity, what, lower);
      sh_d_.allocate(capacity, what, lower);
      sh_ct_.allocate(capacity, what, lower);
      sh_L_.allocate(capacity, what, lower);
    }
    if (shadows.pairs) {
      sh_d2_.allocate(capacity, what, lower);
      sh_c2_.allocate(capacity, what, lower);
    }
    ctr_.allocate(1, what, lower);
    PB_CUDA_CHECK(cudaMallocHost(&host_ctr_, sizeof(WaveCounters)));
  }
  ~PathPool() { if (host_ctr_) cudaFreeHost(host_ctr_); }
  PathPool(const PathPool&) = delete;
  PathPool& operator=(const PathPool&) = delete;

  // Per path: two state buffers (current and next), the hit, and where the settings
  // trace shadow rays one shadow record (a second ray's 24 bytes where pairs occur).
  static uint64_t state_bytes(ShadowUse shadows) {
    return 2 * Buffers::bytes_per_path() + sizeof(uint32_t) +
           (shadows.records ? 3 * sizeof(float4) + sizeof(float2) : 0) +
           (shadows.pairs ? sizeof(float4) + sizeof(float2) : 0);
  }

  FrameResult run(Launcher& launch, cudaStream_t stream, const GpuScene::Impl& g, const PathConfig& c, uint32_t spp,
                  uint64_t total, FilmDev film, bool variance) {
    PB_CUDA_CHECK(cudaMemsetAsync(ctr_.get(), 0, sizeof(WaveCounters), stream));
    const ShadowSoA sh{sh_o_.get(), sh_d_.get(), sh_ct_.get(), sh_L_.get(), sh_d2_.get(), sh_c2_.get()};
    WaveCounters* ctr = ctr_.get();
    const uint32_t cap = uint32_t(capacity_);
    FrameResult r;
    constexpr int kCheckEvery = 4;  // iterations between looks at the counters
    for (uint64_t it = 0;; ++it) {
      const PathSoA cur = buf_[it & 1].view(), next = buf_[(it + 1) & 1].view();
      launch.launch("schedule", k_wf_schedule, 1, ctr, static_cast<unsigned long long>(total), cap);
      launch.launch("generate", k_wf_generate, 0, g.view, c, cur, ctr, spp);
      launch.launch("intersect", k_wf_intersect, 0, g.bvh, cur, prim_.get(), ctr);
      with_features(g.view.material_kinds, [&](auto kinds) {  // shade compiled for the scene's kinds
        constexpr uint32_t K = decltype(kinds)::value;
        if (variance) launch.launch("shade", k_wf_shade<true, K>, 0, g.view, c, cur, next, prim_.get(), sh, ctr, film);
        else launch.launch("shade", k_wf_shade<false, K>, 0, g.view, c, cur, next, prim_.get(), sh, ctr, film);
      });
      if (shadows_.records) {
        if (variance) launch.launch("shadow", k_wf_shadow<true>, 0, g.bvh, sh, next, ctr, film);
        else launch.launch("shadow", k_wf_shadow<false>, 0, g.bvh, sh, next, ctr, film);
      }
      if (it % kCheckEvery == kCheckEvery - 1) {
        PB_CUDA_CHECK(cudaMemcpyAsync(host_ctr_, ctr, sizeof(WaveCounters), cudaMemcpyDeviceToHost, stream));
        PB_CUDA_CHECK(cudaStreamSynchronize(stream));
        if (host_ctr_->live == 0 && host_ctr_->next_sample >= total) {
          r.iterations = it + 1;
          break;
        }
      }
    }
    // The last schedule booked every iteration; every generated path has ended.
    r.stats = host_ctr_->stats;
    r.stats.paths = r.stats.camera;
    r.state_bytes_per_path = state_bytes(shadows_);
    r.queue_bytes_per_path = 0;  // the queues are the compacted state buffers themselves
    r.paths_in_flight = capacity_;
    r.pool_bytes = capacity_ * state_bytes(shadows_) + sizeof(WaveCounters);
    return r;
  }

 private:
  struct Buffers {
    DeviceBuffer<float4> o, d, beta, L;
    void allocate(uint64_t n, const char* what, const char* lower) {
      o.allocate(n, what, lower);
      d.allocate(n, what, lower);
      beta.allocate(n, what, lower);
      L.allocate(n, what, lower);
    }
    PathSoA view() const { return {o.get(), d.get(), beta.get(), L.get()}; }
    static uint64_t bytes_per_path() { return 4 * sizeof(float4); }
  };
  uint64_t capacity_;
  ShadowUse shadows_;
  Buffers buf_[2];
  DeviceBuffer<uint32_t> prim_;
  DeviceBuffer<float4> sh_o_, sh_d_, sh_L_, sh_d2_;
  DeviceBuffer<float2> sh_ct_, sh_c2_;
  DeviceBuffer<WaveCounters> ctr_;
  WaveCounters* host_ctr_ = nullptr;
};

FrameResult run_pixel(Launcher& launch, cudaStream_t stream, const GpuScene::Impl& g, const PathConfig& c, uint32_t spp,
                      uint64_t total, FilmDev film, bool variance, Precision precision, bool watertight,
                      DeviceBuffer<Stats>& stats) {
  PB_CUDA_CHECK(cudaMemsetAsync(stats.get(), 0, sizeof(Stats), stream));
  // The megakernel compiled for the scene's material kinds (features.h).
  // In float with the watertight test, or (the accuracy study's variants) in double or
  // with Moeller-Trumbore.
  with_features(g.view.material_kinds, [&](auto kinds) {
    constexpr uint32_t K = decltype(kinds)::value;
    auto go = [&](auto kernel) { launch.launch("pixel", kernel, 0, g.view, g.bvh, c, spp, total, film, stats.get()); };
    if (precision == Precision::Double) variance ? go(k_pixel<true, K, double, true>) : go(k_pixel<false, K, double, true>);
    else if (!watertight) variance ? go(k_pixel<true, K, float, false>) : go(k_pixel<false, K, float, false>);
    else variance ? go(k_pixel<true, K, float, true>) : go(k_pixel<false, K, float, true>);
  });
  FrameResult r;
  PB_CUDA_CHECK(cudaMemcpyAsync(&r.stats, stats.get(), sizeof(Stats), cudaMemcpyDeviceToHost, stream));
  PB_CUDA_CHECK(cudaStreamSynchronize(stream));
  r.state_bytes_per_path = 0;  // in registers
  return r;
}

void render_impl(const Scene& scene, const GpuScene& gpu_scene, const RenderSettings& settings, Film& film,
                 RunReport& report, bool profile);
}  // namespace

void render(const Scene& scene, const RenderSettings& settings, Film& film, RunReport& report, bool profile) {
  ensure_device();
  settings.validate();
  // Start the context before measuring memory: its own use is not the tracer's.
  PB_CUDA_CHECK(cudaFree(nullptr));
  DeviceMemory::instance().begin_measurement();
  GpuScene gpu_scene(scene);
  render_impl(scene, gpu_scene, settings, film, report, profile);
}

void render(const Scene& scene, const GpuScene& gpu_scene, const RenderSettings& settings, Film& film, RunReport& report,
            bool profile) {
  ensure_device();
  settings.validate();
  DeviceMemory::instance().begin_measurement();
  render_impl(scene, gpu_scene, settings, film, report, profile);
}

namespace {
void render_impl(const Scene& scene, const GpuScene& gpu_scene, const RenderSettings& settings, Film& film,
                 RunReport& report, bool profile) {
  if (film.width() != settings.width || film.height() != settings.height)
    throw std::logic_error("film size does not match the settings");
  const DeviceInfo info = device_info();
  const GpuScene::Impl& g = gpu_scene.impl();
  DeviceMemory& mem = DeviceMemory::instance();

  const PathConfig config = settings.path_config();
  const uint32_t pixels = settings.width * settings.height;
  const uint64_t total = settings.total_samples();
  const ShadowUse shadows = ShadowUse::of(scene, settings);
  film.begin(settings.spp, scene.max_emission());

  ScopedStream stream;
  Launcher launch(stream.s, profile);
  FilmBuffers fb;
  fb.allocate(film, pixels);

  if (settings.strategy != Strategy::Pixel && settings.precision != Precision::Float)
    throw InputError(fmt::format("--precision {}: the GPU runs double precision with --strategy pixel only (its "
                                 "wavefront state is float4 arrays)", to_string(settings.precision)));
  if (settings.strategy != Strategy::Pixel && !settings.watertight)
    throw InputError("--no-watertight: the GPU runs the Moeller-Trumbore triangle test with --strategy pixel only");

  // Strategy resources.
  std::unique_ptr<PathPool> pool;
  DeviceBuffer<Stats> pixel_stats;
  uint64_t warmup_total = std::min<uint64_t>(total, pixels);
  if (settings.strategy == Strategy::Pixel) {
    pixel_stats.allocate(1, "counters", "nothing (8 bytes)");
  } else if (settings.strategy == Strategy::Wavefront) {
    uint64_t pif = settings.paths_in_flight ? settings.paths_in_flight : default_paths_in_flight();
    pif = std::min<uint64_t>(pif, total);
    pif = std::max<uint64_t>(pif, 1);
    if (pif > 0xFFFFFFFFull) throw InputError("--paths-in-flight: at most 4294967295 paths");
    pool = std::make_unique<PathPool>(pif, shadows, "the wavefront path pool", "--paths-in-flight");
  } else {
    // The paper's global queue: a task for every path of the frame, all at once.
    const uint64_t per_task = PathPool::state_bytes(shadows);
    const uint64_t need = total * per_task;
    const uint64_t free_b = DeviceMemory::free_bytes();
    if (total > 0xFFFFFFFFull || need + (64ull << 20) > free_b)
      throw InputError(fmt::format(
          "--strategy paper-queue: the paper's global queue holds every path of the frame up front: {}x{} pixels x {} "
          "spp = {} tasks x {} bytes = {:.2f} GB, but the GPU ({}) has {:.2f} GB free{}; lower --spp or "
          "--width/--height, or use --strategy wavefront (memory bounded by --paths-in-flight)",
          settings.width, settings.height, settings.spp, total, per_task, need / 1e9, info.name, free_b / 1e9,
          total > 0xFFFFFFFFull ? " (and more than 2^32 - 1 tasks cannot be indexed)" : ""));
    pool = std::make_unique<PathPool>(total, shadows, "the paper-queue global task queue", "--spp or --width/--height");
    warmup_total = total;  // its warm-up is the frame itself: the queue is sized for it
  }

  auto run_frame = [&](uint64_t n) {
    if (settings.strategy == Strategy::Pixel)
      return run_pixel(launch, stream.s, g, config, settings.spp, n, fb.view, film.has_variance(), settings.precision,
                       settings.watertight, pixel_stats);
    return pool->run(launch, stream.s, g, config, settings.spp, n, fb.view, film.has_variance());
  };

  // Warm-up (module load, first-touch of every buffer), then the timed frame.
  fb.clear(stream.s);
  run_frame(warmup_total);
  PB_CUDA_CHECK(cudaStreamSynchronize(stream.s));
  mem.sample();
  launch.clear();
  fb.clear(stream.s);

  ScopedEvent ev0, ev1;
  PB_CUDA_CHECK(cudaStreamSynchronize(stream.s));
  const auto t0 = std::chrono::steady_clock::now();
  PB_CUDA_CHECK(cudaEventRecord(ev0.e, stream.s));
  const FrameResult r = run_frame(total);
  PB_CUDA_CHECK(cudaEventRecord(ev1.e, stream.s));
  PB_CUDA_CHECK(cudaEventSynchronize(ev1.e));
  const auto t1 = std::chrono::steady_clock::now();
  mem.sample();
  float device_ms = 0;
  PB_CUDA_CHECK(cudaEventElapsedTime(&device_ms, ev0.e, ev1.e));

  // Film back to the host: the device's unsigned sums are Film's int64 sums mod 2^64.
  static_assert(sizeof(unsigned long long) == sizeof(int64_t));
  fb.sum.download(reinterpret_cast<unsigned long long*>(film.raw_sums().data()), fb.sum.size());
  fb.count.download(film.counts().data(), fb.count.size());
  if (film.has_variance()) fb.sum_sq.download(film.raw_sum_sq().data(), fb.sum_sq.size());

  report.scene = scene.name;
  report.triangles = scene.triangles.size();
  report.settings = settings;
  report.seconds = std::chrono::duration<double>(t1 - t0).count();
  report.device_seconds = double(device_ms) / 1e3;
  report.rays.camera = r.stats.camera;
  report.rays.bounce = r.stats.bounce;
  report.rays.shadow = r.stats.shadow;
  report.paths = r.stats.paths;
  report.discarded_samples = r.stats.discarded;
  report.state_bytes_per_path = r.state_bytes_per_path;
  report.paths_in_flight = r.paths_in_flight;
  report.threads = 0;
  report.peak_host_bytes = peak_resident_bytes();
  report.tracer_host_bytes = film.bytes();
  report.peak_device_bytes = std::max(mem.peak_allocated(), mem.peak_meminfo_delta());
  auto& x = report.extra;
  x["gpu"] = {{"name", info.name},
              {"slug", info.slug},
              {"compute_capability", fmt::format("{}.{}", info.compute_major, info.compute_minor)},
              {"multiprocessors", info.multiprocessors},
              {"memory_bytes", info.total_memory},
              {"driver_version", kernel_driver_version()},
              {"driver_cuda_version", fmt::format("{}.{}", info.driver_version / 1000, (info.driver_version % 1000) / 10)},
              {"cuda_runtime_version", fmt::format("{}.{}", info.runtime_version / 1000, (info.runtime_version % 1000) / 10)},
              {"cuda_architectures_built", PATHBENCH_CUDA_ARCHS}};
  x["device_bytes_allocated_peak"] = mem.peak_allocated();
  x["device_bytes_meminfo_delta_peak"] = mem.peak_meminfo_delta();
  x["film_device_bytes"] = fb.bytes();
  x["scene_device_bytes"] = g.bytes;
  x["bvh"] = {{"nodes", g.bvh.num_nodes}, {"triangle_refs", g.bvh.num_tris}, {"leaves", g.bvh_leaves},
              {"depth", g.bvh_depth}, {"sah_cost", g.bvh_sah}, {"build_seconds", g.bvh_build_seconds},
              {"builder", "embree rtcBuildBVH, binned SAH, binary"}};
  x["device_samples_per_second"] = device_ms > 0 ? double(r.stats.paths) / (device_ms / 1e3) : 0.0;
  x["device_rays_per_second"] = device_ms > 0 ? double(report.rays.total()) / (device_ms / 1e3) : 0.0;
  if (const char* commit = std::getenv("PATHBENCH_SOURCE_COMMIT")) x["source_commit"] = commit;
  x["timing"] = "device_seconds: CUDA events around the frame, after a warm-up frame";
  if (settings.strategy != Strategy::Pixel) {
    x["state_layout"] = std::string("2 x (o+pdf, d+pixel, beta+depth, L+sample: float4) + hit u32") +
                        (shadows.records ? " + shadow record (o, d: float4; c.z+target: float2; L of a finished path: float4)" : "") +
                        (shadows.pairs ? " + a pair's second ray (d: float4; c.yz: float2)" : "");
    x["pool_device_bytes"] = r.pool_bytes;
    x["iterations"] = r.iterations;
  }
  if (settings.strategy == Strategy::PaperQueue) {
    x["bytes_per_task"] = r.state_bytes_per_path + r.queue_bytes_per_path;
    x["tasks"] = total;
  }
  if (settings.strategy == Strategy::Pixel) x["pixel_block"] = launch.block_size("pixel");
  if (profile) {
    const nlohmann::json prof = launch.collect();
    x["profile"] = prof;
    std::fputs(Launcher::format_table(prof).c_str(), stdout);
  }
  if (settings.strategy == Strategy::Pixel)
    x["paths_in_flight_note"] = "pixel: one thread per sample, path state in registers";
}
}  // namespace

// -----------------------------------------------------------------------------------
std::vector<TraceResult> trace_on_device(const Scene& scene, const std::vector<TraceQuery>& rays, bool any_hit) {
  ensure_device();
  const GpuScene gs(scene);
  DeviceBuffer<TraceQuery> d_rays(rays.size(), "test rays", "the number of rays");
  DeviceBuffer<TraceResult> d_out(rays.size(), "test results", "the number of rays");
  d_rays.upload(rays.data(), rays.size());
  std::vector<TraceResult> out(rays.size());
  if (rays.empty()) return out;
  Launcher launch(nullptr, false);
  launch.launch("trace", k_trace, rays.size(), gs.impl().bvh, d_rays.get(), d_out.get(), uint32_t(rays.size()), any_hit);
  PB_CUDA_CHECK(cudaDeviceSynchronize());
  d_out.download(out.data(), out.size());
  return out;
}

std::vector<double> time_trace_on_device(const GpuScene& gs, const std::vector<TraceQuery>& rays, bool any_hit,
                                         int repeats) {
  ensure_device();
  if (rays.empty() || repeats < 1) throw InputError("time_trace_on_device: needs rays and at least one repeat");
  const uint32_t n = uint32_t(rays.size());
  DeviceBuffer<TraceQuery> d_rays(n, "benchmark rays", "the number of rays");
  DeviceBuffer<TraceResult> d_out(n, "benchmark results", "the number of rays");
  d_rays.upload(rays.data(), n);
  Launcher launch(nullptr, false);
  const ScopedEvent start, stop;
  std::vector<double> seconds;
  for (int r = -1; r < repeats; ++r) {  // r = -1: warm-up, not timed
    PB_CUDA_CHECK(cudaMemset(d_out.get(), 0xAB, sizeof(TraceResult) * n));  // poison
    PB_CUDA_CHECK(cudaEventRecord(start.e, nullptr));
    launch.launch("trace", k_trace, n, gs.impl().bvh, d_rays.get(), d_out.get(), n, any_hit);
    PB_CUDA_CHECK(cudaEventRecord(stop.e, nullptr));
    PB_CUDA_CHECK(cudaEventSynchronize(stop.e));
    float ms = 0;
    PB_CUDA_CHECK(cudaEventElapsedTime(&ms, start.e, stop.e));
    if (r >= 0) seconds.push_back(double(ms) * 1e-3);
  }
  std::vector<TraceResult> out(n);
  d_out.download(out.data(), n);
  for (const TraceResult& t : out)
    if (t.prim == 0xABABABABu) throw std::runtime_error("time_trace_on_device: a result was not written");
  return seconds;
}

}  // namespace pb::gpu
