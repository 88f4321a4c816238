#include "materials_bench.h"

#include <string>
#include <vector>

#include "render_bench.h"

namespace pb::bench {

namespace {

std::vector<Device> devices() {
#if PATHBENCH_BENCH_GPU
  return {Device::Cpu, Device::Gpu};  // GPU rows skip themselves without a device
#else
  return {Device::Cpu};
#endif
}

}  // namespace

void preset_materials() {
  // paper-cornell: the diffuse-only scene of the specialisation check. cornell-box and
  // its variants share the room, so diffuse against mixed is the materials alone.
  std::vector<std::string> scenes = {"paper-cornell", "cornell-box"};
#if PATHBENCH_EXTRA_MATERIALS
  for (const char* v : {"mirror", "glass", "ggx", "spheres"}) scenes.push_back(std::string("cornell-box:") + v);
#endif
  for (const std::string& scene : scenes)
    for (Device dev : devices())
      for (Strategy strat : {Strategy::Pixel, Strategy::Wavefront}) {
        RenderCase c;
        c.scene = scene;
        c.settings.device = dev;
        c.settings.strategy = strat;
        c.settings.width = c.settings.height = 128;
        c.settings.spp = 16;
        c.settings.max_bounces = 4;
        c.settings.sampling = Sampling::Nee;
        register_render_benchmark(c);
      }
}

}  // namespace pb::bench
