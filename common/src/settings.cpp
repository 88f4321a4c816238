#include "pathbench/common/settings.h"

#include <unistd.h>

#include <stdexcept>

#include <fmt/core.h>

#include "pathbench/common/errors.h"
#include "pathbench/common/limits.h"

namespace pb {

const char* to_string(Sampling s) {
  switch (s) {
    case Sampling::Uniform: return "uniform";
    case Sampling::Cosine: return "cosine";
    case Sampling::Nee: return "nee";
  }
  return "?";
}
const char* to_string(Strategy s) {
  switch (s) {
    case Strategy::Pixel: return "pixel";
    case Strategy::Wavefront: return "wavefront";
    case Strategy::PaperQueue: return "paper-queue";
  }
  return "?";
}
const char* to_string(Device d) { return d == Device::Cpu ? "cpu" : "gpu"; }
const char* to_string(Precision p) { return p == Precision::Float ? "float" : "double"; }
const char* to_string(EmbreeLayout l) {
  switch (l) {
    case EmbreeLayout::Auto: return "auto";
    case EmbreeLayout::Triangles: return "triangles";
    case EmbreeLayout::Quads: return "quads";
  }
  return "?";
}
const char* to_string(Isa i) {
  switch (i) {
    case Isa::Auto: return "auto";
    case Isa::Avx512: return "avx512";
    case Isa::Avx2: return "avx2";
    case Isa::Scalar: return "scalar";
  }
  return "?";
}

const char* to_string(Instancing i) {
  switch (i) {
    case Instancing::Auto: return "auto";
    case Instancing::On: return "on";
    case Instancing::Off: return "off";
  }
  return "?";
}

Sampling parse_sampling(std::string_view s) {
  if (s == "uniform") return Sampling::Uniform;
  if (s == "cosine") return Sampling::Cosine;
  if (s == "nee") return Sampling::Nee;
  throw InputError(fmt::format("--sampling: unknown sampling '{}' (expected uniform, cosine or nee)", s));
}
Strategy parse_strategy(std::string_view s) {
  if (s == "pixel") return Strategy::Pixel;
  if (s == "wavefront") return Strategy::Wavefront;
  if (s == "paper-queue") return Strategy::PaperQueue;
  throw InputError(fmt::format("--strategy: unknown strategy '{}' (expected pixel, wavefront or paper-queue)", s));
}
Device parse_device(std::string_view s) {
  if (s == "cpu") return Device::Cpu;
  if (s == "gpu") return Device::Gpu;
  throw InputError(fmt::format("--device: unknown device '{}' (expected cpu or gpu)", s));
}
Precision parse_precision(std::string_view s) {
  if (s == "float") return Precision::Float;
  if (s == "double") return Precision::Double;
  throw InputError(fmt::format("--precision: unknown precision '{}' (expected float or double)", s));
}

EmbreeLayout parse_embree_layout(std::string_view s) {
  if (s == "auto") return EmbreeLayout::Auto;
  if (s == "triangles") return EmbreeLayout::Triangles;
  if (s == "quads") return EmbreeLayout::Quads;
  throw InputError(fmt::format("--embree-layout: unknown layout '{}' (expected auto, triangles or quads)", s));
}

Isa parse_isa(std::string_view s) {
  if (s == "auto") return Isa::Auto;
  if (s == "avx512") return Isa::Avx512;
  if (s == "avx2") return Isa::Avx2;
  if (s == "scalar") return Isa::Scalar;
  throw InputError(fmt::format("--isa: unknown instruction set '{}' (expected auto, avx512, avx2 or scalar)", s));
}

Instancing parse_instancing(std::string_view s) {
  if (s == "auto") return Instancing::Auto;
  if (s == "on") return Instancing::On;
  if (s == "off") return Instancing::Off;
  throw InputError(fmt::format("--instancing: unknown choice '{}' (expected auto, on or off)", s));
}

void apply_choices(const RenderChoices& c, RenderSettings& s) {
  s.sampling = parse_sampling(c.sampling);
  s.strategy = parse_strategy(c.strategy);
  s.device = parse_device(c.device);
  s.precision = parse_precision(c.precision);
  s.embree_layout = parse_embree_layout(c.embree_layout);
  s.isa = parse_isa(c.isa);
  s.instancing = parse_instancing(c.instancing);
  if (c.converged) {
    s.max_bounces = -1;
    s.russian_roulette = true;
  }
}

namespace {

// This machine's physical memory in bytes, 0 where it cannot be read.
uint64_t physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : 0;
}

}  // namespace

void check_image_size(uint32_t width, uint32_t height, bool variance) {
  if (width == 0 || height == 0)
    throw InputError(fmt::format("--width/--height: the image must be at least 1x1 (got {}x{})", width, height));
  // In 64 bits: a product of two 32-bit factors cannot wrap, nor pixels (at most 2^28,
  // checked first) times the bytes of a pixel.
  const uint64_t pixels = uint64_t(width) * height;
  if (pixels > limits::kMaxPixels)
    throw InputError(fmt::format("--width/--height: {}x{} is {} pixels, more than the supported {} (16384x16384)",
                                 width, height, pixels, limits::kMaxPixels));
  const uint64_t bytes = pixels * (limits::kFilmBytesPerPixel + (variance ? limits::kVarianceBytesPerPixel : 0));
  if (const uint64_t memory = physical_memory_bytes(); memory > 0 && bytes > memory)
    throw InputError(fmt::format("--width/--height: the film of {}x{} pixels would take {:.1f} GB, more than this "
                                 "machine's {:.1f} GB of memory",
                                 width, height, double(bytes) / 1e9, double(memory) / 1e9));
}

void RenderSettings::validate() const {
  check_image_size(width, height, variance);
  if (spp == 0) throw InputError("--spp: must be at least 1");
  // In 64 bits: pixels (at most 2^28, checked above) x spp (32 bits) cannot wrap.
  const uint64_t pixels = uint64_t(width) * height;
  if (pixels * spp > limits::kMaxFrameSamples)
    throw InputError(fmt::format("--spp: {}x{} pixels at {} spp is {} samples, more than the supported {} (2^48) in "
                                 "one frame",
                                 width, height, spp, pixels * spp, limits::kMaxFrameSamples));
  if (paths_in_flight > limits::kMaxPathsInFlight)
    throw InputError(fmt::format("--paths-in-flight: {} is more than the supported {}", paths_in_flight,
                                 limits::kMaxPathsInFlight));
  if (max_bounces < -1) throw InputError("--bounces: must be >= 0");
  if (max_bounces < 0 && !russian_roulette)
    throw InputError("--converged without Russian roulette would never end a path");
  if (threads < 0) throw InputError("--threads: must be >= 0 (0 = all)");
  // Set by the run layer, never by users: a range outside the frame is a bug, not bad input.
  if (first_sample >= spp || uint64_t(first_sample) + traced_spp() > spp)
    throw std::invalid_argument(fmt::format("sample range [{}, +{}) outside the frame's {} spp", first_sample,
                                            sample_count, spp));
  if (first_row >= height || uint64_t(first_row) + traced_rows() > height)
    throw std::invalid_argument(fmt::format("row range [{}, +{}) outside the frame's {} rows", first_row, row_count,
                                            height));
}

// The strategy/precision/watertight limits of each device's tracer (were checked in
// cpu/src/render.cpp and gpu/src/render.cu; same messages).
void validate_for_tracer(const RenderSettings& s, Device tracer) {
  if (tracer == Device::Cpu) {
    if (s.strategy == Strategy::PaperQueue)
      throw InputError(
          "--strategy paper-queue: the paper's global queue is a GPU strategy; the CPU runs pixel or wavefront");
    return;
  }
  if (s.strategy != Strategy::Pixel && s.precision != Precision::Float)
    throw InputError(fmt::format("--precision {}: the GPU runs double precision with --strategy pixel only (its "
                                 "wavefront state is float4 arrays)", to_string(s.precision)));
  if (s.strategy != Strategy::Pixel && !s.watertight)
    throw InputError("--no-watertight: the GPU runs the Moeller-Trumbore triangle test with --strategy pixel only");
}

}  // namespace pb
