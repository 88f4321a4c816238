#include "pathbench/cpu/embree_scene.h"

#include "pathbench/common/errors.h"
#include "pathbench/cpu/embree_flags.h"

#include <fmt/core.h>

#include <chrono>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace pb::cpu {

namespace {
void on_error(void*, RTCError code, const char* str) {
  fmt::print(stderr, "embree error {}: {}\n", int(code), str ? str : "");
}
}  // namespace

bool EmbreeScene::monitor(void* self_ptr, ssize_t bytes, bool) {
  auto* self = static_cast<EmbreeScene*>(self_ptr);
  int64_t now = self->bytes_.fetch_add(bytes) + bytes;
  int64_t peak = self->peak_bytes_.load();
  while (now > peak && !self->peak_bytes_.compare_exchange_weak(peak, now)) {
  }
  return true;
}

std::unique_ptr<EmbreeScene> make_embree_scene(const Scene& s, bool watertight, EmbreeLayout layout,
                                               Instancing instancing) {
  // Only when asked: Embree tests a copy's triangles in the prototype's coordinates, so at
  // a copy's edges it may name another triangle than the flat scene does (rarely: 2
  // pixels of 30,000 in the worst test scene; docs/notes/cpu-log.md). `auto` keeps the CPU's image
  // the flat one bit for bit; the GPU's two-level BVH is exact and is used under auto.
  if (instancing == Instancing::On && use_instancing(instancing, s.instances.size())) {
    if (layout == EmbreeLayout::Quads && instancing == Instancing::On)
      throw InputError("--instancing on: the instanced Embree scene is built from triangles; it cannot be "
                       "combined with --embree-layout quads (give one of them)");
    if (layout != EmbreeLayout::Quads) return std::make_unique<EmbreeScene>(s, watertight, EmbreeScene::Instanced{});
  }
  TrianglePairs pairs;
  const LayoutChoice choice = layout == EmbreeLayout::Auto ? choose_embree_layout(s, watertight, &pairs)
                                                           : LayoutChoice{layout, 0, 0.0, 0.0, "asked for"};
  // The probe paired the triangles unless its answer was remembered; pair only then.
  if (choice.layout != EmbreeLayout::Quads) pairs = {};
  else if (pairs.quads.empty()) pairs = pair_triangles(s);
  return std::make_unique<EmbreeScene>(s, watertight, choice, std::move(pairs));
}

EmbreeScene::EmbreeScene(const Scene& s, bool watertight, const LayoutChoice& choice, TrianglePairs pairs)
    : choice_(choice), quads_(choice.layout == EmbreeLayout::Quads), pairs_(std::move(pairs)) {
  if (choice_.layout == EmbreeLayout::Auto) throw std::logic_error("EmbreeScene: resolve Auto first (make_embree_scene)");
  if (quads_ && pairs_.quads.empty() && !s.triangles.empty())
    throw std::logic_error("EmbreeScene: the quads layout needs the triangle pairs");
  const auto t0 = std::chrono::steady_clock::now();
  open_device(watertight);
  RTCGeometry geom = rtcNewGeometry(device_, quads_ ? RTC_GEOMETRY_TYPE_QUAD : RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), s.positions.size()));
  std::memcpy(v, s.positions.data(), s.positions.size() * sizeof(Vec3f));
  if (quads_) {
    auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4,
                                                               4 * sizeof(uint32_t), pairs_.quads.size()));
    std::memcpy(idx, pairs_.quads.data(), pairs_.quads.size() * 4 * sizeof(uint32_t));
  } else {
    auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                               3 * sizeof(uint32_t), s.triangles.size()));
    std::memcpy(idx, s.triangles.data(), s.triangles.size() * sizeof(Triangle));
  }
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene_, geom);
  rtcReleaseGeometry(geom);
  commit();
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

EmbreeScene::EmbreeScene(const Scene& s, bool watertight, Instanced)
    : choice_{EmbreeLayout::Triangles, 0, 0.0, 0.0, "instancing (prototypes and the rest as triangles)"},
      instanced_(true) {
  const auto t0 = std::chrono::steady_clock::now();
  open_device(watertight);
  build_instanced(s, watertight);
  commit();
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void EmbreeScene::open_device(bool watertight) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error(fmt::format("embree: cannot create a device (error {})", int(rtcGetDeviceError(nullptr))));
  rtcSetDeviceErrorFunction(device_, on_error, nullptr);
  rtcSetDeviceMemoryMonitorFunction(device_, &EmbreeScene::monitor, this);
  scene_ = rtcNewScene(device_);
  rtcSetSceneFlags(scene_, embree_scene_flags(watertight));
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
}

void EmbreeScene::commit() {
  rtcCommitScene(scene_);
  if (RTCError e = rtcGetDeviceError(device_); e != RTC_ERROR_NONE)
    throw std::runtime_error(fmt::format("embree: building the scene failed (error {})", int(e)));
}

EmbreeScene::~EmbreeScene() {
  if (scene_) rtcReleaseScene(scene_);
  for (RTCScene p : prototypes_) rtcReleaseScene(p);
  if (device_) rtcReleaseDevice(device_);
}

}  // namespace pb::cpu
