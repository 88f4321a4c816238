#pragma once
// What to render and how. RenderSettings is the user's request; PathConfig is the
// part the path step reads, small and plain so it can be passed to kernels by value.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "pathbench/common/hd.h"

namespace pb {

enum class Sampling : uint32_t {
  Uniform = 0,  // uniform hemisphere, no light sampling: the paper's estimator
  Cosine = 1,   // cosine-weighted hemisphere, no light sampling
  Nee = 2,      // light sampling + cosine BSDF sampling, combined by MIS (power heuristic)
};
enum class Strategy : uint32_t { Pixel = 0, Wavefront = 1, PaperQueue = 2 };
enum class Device : uint32_t { Cpu = 0, Gpu = 1 };
// Scalar type of the path step (camera ray, surface_hit, shading, sampling). The
// intersector always finds the hit triangle in float (Embree); with Double the hit
// point is then recomputed in double from the triangle id (surface_hit).
enum class Precision : uint32_t { Float = 0, Double = 1 };
// How the CPU tracer hands the triangles to Embree: one by one, or paired across shared
// edges into Embree quads (cpu/triangle_pairs.h). Which one traces faster depends on
// the scene; Auto measures both on a short probe and keeps the faster
// (cpu/embree_layout.h). The GPU ignores it.
enum class EmbreeLayout : uint32_t { Auto = 0, Triangles = 1, Quads = 2 };
// Instruction set of the CPU tracer's batched path step (cpu/isa.h): Auto takes the
// widest the CPU has (AVX-512: 16 lanes, AVX2: 8), Scalar the reference path step one
// path at a time. Every choice gives the same image bit for bit. The GPU ignores it.
enum class Isa : uint32_t { Auto = 0, Avx512 = 1, Avx2 = 2, Scalar = 3 };
// Whether the acceleration structure is built from the scene's instances (Scene::instances:
// Embree instances on the CPU, a two-level BVH on the GPU) or from the flat, expanded
// triangles. Either way the hit is recomputed on the flat triangle, so shading is the flat
// scene's. Auto: on when the scene has instances. On for a scene without instances traces
// it flat (the report says so). Off: the flat BVH.
enum class Instancing : uint32_t { Auto = 0, On = 1, Off = 2 };

struct PathConfig {
  int32_t max_bounces;        // diffuse reflections; -1 = unbounded (Russian roulette ends paths)
  Sampling sampling;
  bool russian_roulette;
  uint32_t rr_start_depth;    // roulette applies from this bounce on
  uint32_t width, height;
  uint64_t seed;
  // The first sample index this render traces (RenderSettings::first_sample): a sample's
  // index, not its rank or chunk, keys the random stream.
  uint32_t first_sample = 0;
  // The first pixel this render traces (RenderSettings::first_row x width): the traced
  // pixels are [first_pixel, first_pixel + width x traced rows), whole rows.
  uint32_t first_pixel = 0;
  // Samples this render traces per pixel, from first_sample on (RenderSettings::traced_spp()):
  // a sample g of the render is (pixel first_pixel + g / spp, sample first_sample + g % spp).
  uint32_t spp = 0;
};

struct RenderSettings {
  uint32_t width = 256, height = 256;
  uint32_t spp = 16;
  int32_t max_bounces = 2;
  Sampling sampling = Sampling::Nee;
  Strategy strategy = Strategy::Pixel;
  Device device = Device::Cpu;
  uint64_t seed = 0;
  bool russian_roulette = false;  // on by default only with unbounded paths (--converged)
  uint32_t rr_start_depth = 3;
  uint64_t paths_in_flight = 0;  // wavefront pool size; 0 = the device's default
  int threads = 0;               // CPU threads; 0 = all
  bool variance = false;         // also accumulate per-pixel variance
  bool watertight = true;        // watertight ray/triangle test (CPU: Embree's robust mode)
  Precision precision = Precision::Float;  // scalar type of the path step
  EmbreeLayout embree_layout = EmbreeLayout::Auto;  // CPU only
  Isa isa = Isa::Auto;                               // CPU only
  Instancing instancing = Instancing::Auto;          // both devices
  bool progress = true;
  // The samples of every pixel this render traces: [first_sample, first_sample +
  // traced_spp()); sample_count 0 = all spp. The run layer sets them for an MPI rank's
  // share or chunk (run/ranks.h); the film is begun for the whole frame's spp either way,
  // and the random stream is keyed by pixel and sample, so any split gives the same image.
  uint32_t first_sample = 0, sample_count = 0;
  // Likewise the rows traced: [first_row, first_row + traced_rows()); row_count 0 = the
  // rest of the frame. Set by the run layer for a dynamic chunk (run/ranks.h FrameBlock).
  uint32_t first_row = 0, row_count = 0;

  PathConfig path_config() const {
    return {max_bounces, sampling, russian_roulette, rr_start_depth, width, height, seed, first_sample,
            first_row * width, traced_spp()};
  }
  uint64_t total_samples() const { return uint64_t(width) * height * spp; }
  uint32_t traced_spp() const { return sample_count ? sample_count : spp - first_sample; }
  uint32_t traced_rows() const { return row_count ? row_count : height - first_row; }
  uint32_t traced_pixels() const { return width * traced_rows(); }
  uint64_t traced_samples() const { return uint64_t(traced_pixels()) * traced_spp(); }
  // Throws InputError (naming the offending option) on impossible settings.
  void validate() const;
};

// The options users give by name or switch on (`pathbench render` flags, `pathbench.render`
// keywords), turned into RenderSettings in one place (apply_choices) so that the CLI and
// the Python module accept and refuse the same things with the same messages.
struct RenderChoices {
  std::string sampling = "nee", strategy = "pixel", device = "cpu", precision = "float";
  std::string embree_layout = "auto";
  std::string isa = "auto";  // CPU: instruction set of the batched path step
  bool converged = false;  // unbounded paths ended by Russian roulette (max_bounces = -1, rr on)
  std::string instancing = "auto";
};
// Parses the names into `s` and applies `converged`. Throws InputError naming the CLI
// option (--sampling, ...); the Python module renames those to its keywords. The settings
// as a whole are validated once, by the run layer (pathbench/run/run.h) before it renders.
void apply_choices(const RenderChoices& c, RenderSettings& s);

// Throws InputError (naming --width/--height) for an image of no pixels, of more than
// limits::kMaxPixels, or whose film (with `variance` sums) would not fit this machine's
// memory. RenderSettings::validate calls it, and so does Film's constructor, so that no
// caller sizes a film it did not check.
void check_image_size(uint32_t width, uint32_t height, bool variance);

const char* to_string(Sampling s);
const char* to_string(Strategy s);
const char* to_string(Device d);
const char* to_string(Precision p);
const char* to_string(EmbreeLayout l);
const char* to_string(Isa i);
const char* to_string(Instancing i);
Sampling parse_sampling(std::string_view s);  // throw InputError on unknown names
Strategy parse_strategy(std::string_view s);
Device parse_device(std::string_view s);
Precision parse_precision(std::string_view s);
EmbreeLayout parse_embree_layout(std::string_view s);
Isa parse_isa(std::string_view s);
Instancing parse_instancing(std::string_view s);
// Whether `asked` builds the acceleration structure from instances for a scene with
// `instances` instances (Auto and On: where it has any).
constexpr bool use_instancing(Instancing asked, size_t instances) {
  return asked != Instancing::Off && instances > 0;
}

// What the tracer of `tracer` (the device whose kernels trace the samples) can run: the CPU
// has no paper-queue; the GPU runs double precision and the Moeller-Trumbore test with
// --strategy pixel only. Throws InputError naming the option. RenderSettings::validate
// holds the checks every device shares; the run layer calls this once the device is
// there, before any scene is built or film allocated for it (run.cpp, rank_tracer.cpp).
void validate_for_tracer(const RenderSettings& s, Device tracer);

}  // namespace pb
