#pragma once
// One thread's slice of the CPU wavefront (render_wavefront.cpp runs one per thread) and the
// stages it runs, per round:
//   generate (fill free slots with new samples) -> final vertex (paths whose next hit
//   can only add emission: emitter query instead of a closest hit) -> one pass over the
//   live paths: closest hits (packets of W rays), shading (the shared path step), shadow
//   rays (packets of W, traced as soon as W are waiting), and the film for paths that end
// The pass is one loop, not a stage per list: a packet's hits go straight into the
// shading batch, shading routes each path at once (on in `live`, compacted in place; to
// `final`; ended: to the film and `free`), so no list is rebuilt and no path is looked
// at twice per round (docs/notes/cpu-log.md, "Item 5, queue management"). With the batched path
// step the kernel routes, writing the next rays where the next packet reads them
// (PoolSlice::ray, PendingShadows; docs/notes/cpu-log.md, "SoA hand-over"). Per path the order
// stays the path step's: a vertex's shadow ray is answered before the path's next
// vertex is shaded (every pending shadow packet is traced by the end of the pass).
// The film sums are integers, so the order in which paths reach it does not matter.
// Diffuse-only float renders with a vector ISA (--isa; the paper's benchmark) run
// generate, final vertex and shade a vector's width of paths at a time (BatchKernels,
// shade_x8.h: the path step's arithmetic lane-wise in its own order, so the image stays
// bit-identical to the pixel strategy's); everything else runs the scalar path step one
// path at a time. Private to render_wavefront.cpp's translation units (the material kinds
// are compiled per file), hence the unnamed namespace, as wavefront_pool.h.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include "embree_rays.h"
#include "film_combiner.h"
#include "pathbench/common/path.h"
#include "shade_batch.h"
#include "stage_timers.h"
#include "strategies.h"
#include "tiny_scene.h"
#include "wavefront_pool.h"

namespace pb::cpu {
namespace {

// Packet width W: the batch's width, so one batch of rays is one packet: 16 with
// AVX-512, 8 with AVX2 and for the scalar path step. (closest_hits, shadows_blocked,
// embree_closest, embree_occluded: tiny_scene.h.)

// One thread's slice and the stages over it, in scalar type T, compiled for the material
// kinds `Kinds` (features.h), with packets of W rays; `k` (width W) and `table` where the
// batched path step runs (diffuse-only float, a vector ISA), `tiny` where the tiny-scene
// test answers first (tiny_scene.h).
template <class T, uint32_t Kinds, int W> class Slice {
 public:
  Slice(const TraceJob& job, const BatchKernels* k, const ShadeTable* table, const TinyScene* tiny, SampleSource& src,
        size_t paths, Local& local)
      : job_(job), k_(k), table_(table), tiny_(tiny), src_(src), pool_(paths, k != nullptr), local_(local), film_(job.film) {
    rtcInitIntersectContext(&ctx_);
    // path_at_final_vertex as one compare of the depth.
    if (job.config.max_bounces >= 0 && job.scene.num_emitters <= kMaxEmittersForFinalQuery)
      final_depth_ = uint32_t(job.config.max_bounces);
    init_packet_constants(hit_packet_.ray);
    init_packet_constants(shadow_packet_);
    reset_packet(hit_packet_);
    reset_packet(shadow_packet_);
  }

  void run() {
    for (;;) {
      generate();
      if (pool_.n_live == 0 && pool_.n_final == 0) break;
      finished_ = 0;
      final_vertex();
      trace_live();
      if (shadows_.n > 0) trace_shadows();
      local_.paths += finished_;
      job_.progress.advance(finished_);
    }
    film_.flush();
    // Every closest-hit query of a depth-0 path is its camera ray (count_ray).
    local_.rays.camera += camera_;
    local_.rays.bounce += closest_ - camera_;
  }

 private:
  // Free slots get new samples: `live`, or `final` where a path's first vertex is its last.
  PB_CPU_FLATTEN void generate() {
    PB_STAGE(kCamera);
    uint64_t n = pool_.n_free;
    if (n == 0) return;
    const uint64_t start = src_.claim(n);
    if (n == 0) return;
    const bool at_final = final_depth_ == 0;
    std::vector<uint32_t>& to = at_final ? pool_.final : pool_.live;
    uint32_t& count = at_final ? pool_.n_final : pool_.n_live;
    if (!at_final) camera_ += n;
    SampleSource::Cursor at = src_.at(start);
    uint32_t* free = pool_.free.data();
    uint32_t n_free = pool_.n_free, out = count;
    if constexpr (std::is_same_v<T, float>) {
      if (k_) {
        const int width = k_->lanes;
        for (uint64_t i = 0; i < n; i += uint64_t(width)) {
          const int lanes = int(std::min<uint64_t>(uint64_t(width), n - i));
          // Live paths' rays by their place in `live` (final ones: only the state's).
          float* rays[6];
          for (int j = 0; j < 6; ++j) rays[j] = pool_.ray[j].data() + out;
          uint32_t px[kMaxShadeLanes], smp[kMaxShadeLanes];
          PathState<float>* st[kMaxShadeLanes];
          for (int l = 0; l < lanes; ++l) {
            px[l] = at.pixel;
            smp[l] = at.sample;
            src_.step(at);
            const uint32_t slot = free[--n_free];
            st[l] = &pool_.state[slot];
            to[out++] = slot;
          }
          for (int l = lanes; l < width; ++l) {  // idle lanes repeat lane 0 and store nothing
            px[l] = px[0];
            smp[l] = smp[0];
            st[l] = st[0];
          }
          k_->begin_paths(job_.scene, job_.config, px, smp, st, lanes, at_final ? nullptr : rays);
        }
        pool_.n_free = n_free;
        count = out;
        return;
      }
    }
    for (uint64_t i = 0; i < n; ++i, src_.step(at)) {
      const uint32_t slot = free[--n_free];
      path_begin(job_.scene, job_.config, at.pixel, at.sample, pool_.state[slot]);
      to[out++] = slot;
    }
    pool_.n_free = n_free;
    count = out;
  }

  // The paths in `final`: their emitter query (path_final_query); an occlusion test
  // where one faces the ray; then they are done. With kernels, k->lanes paths at a time
  // are first screened for an emitter along their ray (shade_x8.h); the scalar query
  // runs only for the lanes that may have one, and gives every path what it would have
  // given it anyway.
  PB_CPU_FLATTEN void final_vertex() {
    PB_STAGE(kFinal);
    const uint32_t n = pool_.n_final;
    pool_.n_final = 0;
    auto query = [&](uint32_t slot) {
      const PathState<T>& st = pool_.state[slot];
      ShadowQuery<T> q;
      if (path_final_query<Kinds>(job_.scene, job_.config, st, q)) {
        count_ray(local_.rays, st.depth, &RayCounts::shadow);
        queue_shadow(slot | ShadeStream::kEnds, q);
      } else {
        finish(slot);
      }
    };
    const uint32_t* slots = pool_.final.data();
    if constexpr (std::is_same_v<T, float>) {
      if (k_) {
        const int width = k_->lanes;
        for (uint32_t base = 0; base < n; base += uint32_t(width)) {
          const int lanes = int(std::min<uint32_t>(uint32_t(width), n - base));
          PathState<float>* st[kMaxShadeLanes];
          for (int i = 0; i < width; ++i) st[i] = &pool_.state[slots[base + uint32_t(i < lanes ? i : 0)]];
          bool candidate[kMaxShadeLanes];
          k_->final_vertex_candidates(job_.scene, st, candidate);
          for (int i = 0; i < lanes; ++i) {
            if (candidate[i]) query(slots[base + uint32_t(i)]);
            else finish(slots[base + uint32_t(i)]);
          }
        }
        return;
      }
    }
    for (uint32_t i = 0; i < n; ++i) query(slots[i]);
  }

  // One pass over `live`: closest hits a packet at a time, each hit shaded (a batch at a
  // time with kernels), each path routed at once; `live` keeps the paths that go on, in
  // place (a path is written back only after it was read).
  PB_CPU_FLATTEN void trace_live() {
    const uint32_t n_live = pool_.n_live;
    keep_ = 0;
    closest_ += n_live;
    for (uint32_t base = 0; base < n_live; base += W) {
      const int n = int(std::min<uint32_t>(W, n_live - base));
      // Read in place: routing writes `live` only below the paths routed so far, all of
      // which were read before (lane i's slot is read before any path after it is routed).
      const uint32_t* slots = &pool_.live[base];
      uint32_t prim[W];
      closest(base, slots, n, prim);
      if constexpr (std::is_same_v<T, float> && Kinds == kDiffuseOnly) {
        if (table_) {
          batch_hits(slots, prim, n);
          continue;
        }
      }
      for (int i = 0; i < n; ++i) {
        if (prim[i] == RTC_INVALID_GEOMETRY_ID) finish(slots[i]);
        else shade(slots[i], prim[i]);
      }
    }
    if constexpr (std::is_same_v<T, float> && Kinds == kDiffuseOnly)
      if (batch_.lanes > 0) shade_batch();
    pool_.n_live = keep_;
  }

  // The hit triangle (or RTC_INVALID_GEOMETRY_ID) of each of the n <= W paths' rays
  // (those of live[base, base + n)): one packet; with `tiny` (and k) the tiny-scene test
  // answers first, Embree only where it is unsure. With k the rays are read in place
  // from the pool's arrays (copied into the packet only for Embree).
  void closest(uint32_t base, const uint32_t* slots, int n, uint32_t* prim) {
    // tfar and geomID hold their start values here (reset_packet after each Embree call).
    if (k_) {
      const float* rays[6];
      for (int j = 0; j < 6; ++j) rays[j] = pool_.ray[j].data() + base;
      PB_STAGE(kClosest);
      closest_hits<W>(*k_, tiny_, job_.embree, ctx_, rays, hit_packet_, n, prim);
      return;
    }
    for (int i = 0; i < n; ++i) set_lane(hit_packet_.ray, i, pool_.state[slots[i]].ray, kInfinity);
    embree_closest<W>(job_.embree, ctx_, hit_packet_, n, prim);
  }

  // A packet's hits into the shading batch (as shade() does, with the pool's pointers and
  // the batch's count in registers: ~20 instructions a hit instead of ~32).
  void batch_hits(const uint32_t* slots, const uint32_t* prim, int n) {
    if constexpr (std::is_same_v<T, float> && Kinds == kDiffuseOnly) {
      PathState<float>* const state = pool_.state.data();
      int b = batch_.lanes;
      for (int i = 0; i < n; ++i) {
        const uint32_t slot = slots[i];
        if (prim[i] == RTC_INVALID_GEOMETRY_ID) {
          finish(slot);
          continue;
        }
        batch_.st[b] = state + slot;
        batch_.prim[b] = prim[i];
        batch_.tag[b] = slot;
        if (++b == W) {
          batch_.lanes = W;
          shade_batch();
          b = 0;
        }
      }
      batch_.lanes = b;
    }
  }

  // The path step at one hit (path_hit); batch_hits where the batched step runs.
  void shade(uint32_t slot, uint32_t prim) {
    PathState<T>& st = pool_.state[slot];
    bool wants_shadow;
    ShadowQuery<T> q;
    const PathEvent ev = path_hit<Kinds>(job_.scene, job_.config, st, surface_hit(job_.scene, prim, st.ray), q, wants_shadow);
    const bool cont = ev == PathEvent::Continue;
    if (wants_shadow) {
      ++local_.rays.shadow;
      queue_shadow(cont ? slot : slot | ShadeStream::kEnds, q);
    }
    if (cont) {
      if (st.depth >= final_depth_) pool_.final[pool_.n_final++] = slot;
      else pool_.live[keep_++] = slot;
    } else if (!wants_shadow) {
      finish(slot);
    }
  }

  // The batch's paths through k.shade_diffuse (shade_x8.h), bit-identical to path_hit;
  // the kernel routes them (ShadeBatch's streams): going on to `live` (its rays to the
  // pool's arrays at the same place) or `final`, shadow rays to the pending ones; the
  // paths that ended without one go to the film here.
  void shade_batch() {
    if constexpr (std::is_same_v<T, float> && Kinds == kDiffuseOnly) {
      ShadeBatch& b = batch_;
      const int lanes = b.lanes;
      for (int i = lanes; i < W; ++i) {  // idle lanes repeat lane 0
        b.st[i] = b.st[0];
        b.prim[i] = b.prim[0];
        b.tag[i] = b.tag[0];
      }
      ShadeStream next{}, to_final{}, shadow = shadows_.stream();
      for (int j = 0; j < 6; ++j) next.ray[j] = pool_.ray[j].data();
      next.tag = pool_.live.data();
      next.n = keep_;
      to_final.tag = pool_.final.data();
      to_final.n = pool_.n_final;
      b.final_depth = final_depth_;
      b.next = &next;
      b.final = &to_final;
      b.shadow = &shadow;
      {
        PB_STAGE(kShade);
        k_->shade_diffuse(job_.scene, job_.config, *table_, b);
      }
      b.lanes = 0;
      keep_ = next.n;
      pool_.n_final = to_final.n;
      local_.rays.shadow += shadow.n - shadows_.n;
      shadows_.n = shadow.n;
      for (uint32_t done = b.done; done != 0; done &= done - 1) finish(b.tag[__builtin_ctz(done)]);
      while (shadows_.n >= uint32_t(W)) trace_shadows();
    }
  }

  // A shadow ray (slot | ShadeStream::kEnds where its path is done once it is answered)
  // waits for a full packet.
  void queue_shadow(uint32_t slot_and_ends, const ShadowQuery<T>& q) {
    shadows_.push(slot_and_ends, q);
    if (shadows_.n == uint32_t(W)) trace_shadows();
  }

  // The first W (or fewer, at the end of a pass) pending shadow rays as one packet (the
  // tiny test first where it applies).
  void trace_shadows() {
    PendingShadows<T, W>& sb = shadows_;
    const int n = int(std::min<uint32_t>(sb.n, W));
    RTCRayNt<W>& p = shadow_packet_;
    const float* rays[6];
    for (int j = 0; j < 6; ++j) rays[j] = sb.ray[j];
    bool blocked[W];  // tfar holds 1 here (reset_packet after each Embree call)
    PB_STAGE(kShadow);
    if (k_) {
      shadows_blocked<W>(*k_, tiny_, job_.embree, ctx_, rays, p, n, blocked);
    } else {
      copy_rays<W>(rays, p);
      embree_occluded<W>(job_.embree, ctx_, p, n, blocked);
    }
    for (int i = 0; i < n; ++i) {
      const uint32_t slot = sb.tag[i] & ~ShadeStream::kEnds;
      if (!blocked[i])  // shadow_unoccluded
        pool_.state[slot].L += Vec3<T>{sb.contribution[0][i], sb.contribution[1][i], sb.contribution[2][i]};
      if (sb.tag[i] & ShadeStream::kEnds) finish(slot);
    }
    sb.drop(uint32_t(n));
  }

  // A path is done: its radiance to the film, its slot free.
  void finish(uint32_t slot) {
    if (!film_.add(pool_.state[slot].pixel, Vec3f(pool_.state[slot].L))) ++local_.discarded;
    pool_.free[pool_.n_free++] = slot;
    ++finished_;
  }

  const TraceJob& job_;
  const BatchKernels* k_;
  const ShadeTable* table_;
  const TinyScene* tiny_;
  SampleSource& src_;
  PoolSlice<T> pool_;
  Local& local_;
  FilmCombiner film_;
  RTCIntersectContext ctx_;
  uint32_t final_depth_ = std::numeric_limits<uint32_t>::max();  // never, without the final query
  alignas(64) RTCRayHitNt<W> hit_packet_;
  alignas(64) RTCRayNt<W> shadow_packet_;
  ShadeBatch batch_{};  // tags: pool slots
  PendingShadows<T, W> shadows_;
  uint32_t keep_ = 0;                            // paths kept in `live` by the pass so far
  uint64_t finished_ = 0;                        // paths done this round
  uint64_t camera_ = 0, closest_ = 0;            // closest-hit queries: of new paths, in all
};

}  // namespace
}  // namespace pb::cpu
