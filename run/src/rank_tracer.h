#pragma once
// One rank's tracer for the rank render (ranks_render.cpp): settings checked and the
// device's scene (Embree's, or the GPU's BVH) built once, then any number of sample chunks traced into one film.
#include <memory>

#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"
#include "pathbench/run/ranks.h"
#include "pathbench/run/run.h"
#include "pathbench/run/tracer.h"

namespace pb::bvh {
class HostGpuTracer;
}

namespace pb::run {

class RankTracer {
 public:
  // Validates `settings`, checks the device, and on the GPU uploads the scene once.
  // Throws InputError like run::render. `gpu_samples`: a CPU rank in a frame with GPU
  // ranks traces the GPU's samples bit for bit (bvh/host_tracer.h), not Embree's, so
  // that the image does not depend on which device took which samples.
  RankTracer(const Scene& scene, const RenderSettings& settings, const RunOptions& options, bool gpu_samples = false);
  // What traces this rank's samples: "embree", "gpu", or "gpu-bvh-on-host".
  const char* tracer() const;
  ~RankTracer();
  // Traces `block` of the frame into `film` (begun for the whole frame, and holding
  // nothing but this tracer's earlier blocks), and adds the block's rays, paths,
  // discarded samples and times into `report`. A GPU rank's blocks add up on the device
  // until finish().
  void trace(const FrameBlock& block, Film& film, RunReport& report);
  // Before the frame's clock starts (film sized and begun): a GPU rank's warm-up, as one
  // GPU process warms up before its timed frame. Nothing on the CPU.
  void warm_up(Film& film);
  // Before the frame's clock starts (after warm_up): traces `block` as a probe and returns
  // its seconds, leaving the film (host and device) cleared and this tracer as if it had
  // traced nothing: dynamic balancing then starts from every rank's measured rate.
  double calibrate(const FrameBlock& block, Film& film, float max_emission);
  // After the rank's last block: a GPU rank's film comes back from the device (once).
  void finish(Film& film, RunReport& report);
  // A GPU rank's film on the device (what finish() downloads), for a reduction on the
  // GPUs; null on a CPU rank or before the first block.
  DeviceFilm* device_film();

 private:
  RenderSettings settings_;
  RunOptions options_;
  std::unique_ptr<PreparedScene> scene_;           // Embree's scene or the GPU's uploaded BVH (tracer.h), or
  std::unique_ptr<bvh::HostGpuTracer> host_bvh_;  // the GPU's samples on this CPU
  std::unique_ptr<DeviceFilm> device_film_;        // a GPU rank's: every block's samples, downloaded once (finish)
  int chunks_ = 0;
};

}  // namespace pb::run
