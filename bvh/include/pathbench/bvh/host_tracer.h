#pragma once
// The GPU tracer's samples computed on the CPU: the megakernel's path loop
// (path_trace.h) over the BVH the GPU would build for the scene (built here, on the
// host), TBB over rows of pixels. Every sample is what the GPU computes for it, bit for
// bit; the price is speed (this traversal is plain C++, far slower than Embree's). For a
// CPU working beside GPUs on one frame (the hybrid CPU+GPU render, run/'s RankTracer):
// then the frame's image is one GPU's whichever device took which samples. In every
// build, with or without CUDA (pathbench::bvh).
#include <cstdint>
#include <string>

#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb::bvh {

class HostGpuTracer {
 public:
  // Builds the BVH as the GPU tracer does (GpuBvhOptions::from_env(), with the
  // render's --instancing). `scene` must outlive the tracer.
  explicit HostGpuTracer(const Scene& scene, Instancing instancing = Instancing::Off);
  // Traces samples [first_sample, first_sample + traced_spp()) of every pixel into
  // `film` (begun by the caller; Film::add, so a sample the GPU would discard is
  // discarded here too) on settings.threads threads (0: all), and adds the rays, paths,
  // discarded samples and seconds to `report`.
  void render(const RenderSettings& settings, Film& film, RunReport& report) const;
  std::string layout() const { return to_string(bvh_.layout); }
  uint64_t bvh_bytes() const { return bvh_.bytes(); }
  const SceneBvhHost& bvh() const { return bvh_; }

 private:
  const Scene& scene_;
  SceneBvhHost bvh_;
};

}  // namespace pb::bvh
