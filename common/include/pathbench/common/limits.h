#pragma once
// The ranges pathbench supports, in one place: every reader and every check (scene
// finalize, the scene-file readers, the Python ray arrays, compare's readers) uses
// these constants, and docs/reference.md ("Scenes and supported ranges") documents them. Input outside them is a user error
// (InputError: exit 2, or ValueError in Python), refused before Embree or the film
// sees it.
#include <cstdint>

namespace pb::limits {

// Largest |coordinate| of a vertex (after a mesh's transform), of the camera position
// and of a ray origin or direction component. Embree asserts (and aborts the process)
// on ray origins or directions beyond about 1.8e18; 1e15 leaves a margin of ~1800 for
// hit points and offsets, and keeps a scene-sized distance squared (~1e31) far inside
// float range.
inline constexpr double kMaxCoordinate = 1e15;

// Largest emitted radiance per channel. The film sums samples in 64-bit fixed point
// scaled from the brightest emission, and a sample is computed in float (max 3.4e38):
// a path may carry up to ~1024 x the emission (MIS, bounces), so 1e20 leaves ~1e15 of
// headroom for throughput and geometry terms before a sample overflows to infinity.
inline constexpr double kMaxEmission = 1e20;

// Triangles in one scene (after triangulating OBJ polygons). Above scaling:10^7, the
// largest built-in scene; bounds memory (scene + Embree BVH stay a few GB).
inline constexpr uint64_t kMaxTriangles = uint64_t(1) << 24;
// Triangles in one scene counting those its instances expand into (JSON "instances",
// Mitsuba instances, glTF nodes): the suite's instanced workload has over 10^8. The
// expansion costs about 22 bytes a triangle on the host (2.2 GB at 10^8); the
// acceleration structure is small with --instancing on, and a flat one of that many
// triangles needs a large machine. Triangles outside instances stay under kMaxTriangles.
inline constexpr uint64_t kMaxInstancedTriangles = uint64_t(1) << 28;

// Vertices in one scene: three per triangle at most are ever used, so a file that
// declares more (a PLY vertex element, glTF POSITION accessors) is refused before
// they are read.
inline constexpr uint64_t kMaxVertices = 3 * kMaxTriangles;

// Placements in one scene: instances of a mesh (JSON "instances", Mitsuba instance
// shapes) and glTF node placements (a node shared by several parents is placed once
// per path to it). Counted before any geometry is read, so a small file cannot ask
// for 2^31 copies.
inline constexpr uint64_t kMaxPlacements = uint64_t(1) << 20;

// glTF's JSON (a .gltf, or a .glb's JSON chunk) before tinygltf parses it: nesting
// depth (its parser recurses per level) and values (a parsed value costs it ~200
// bytes, a node ~700 bytes and ~10 us): at most kMaxGltfJsonValues.
inline constexpr uint64_t kMaxGltfJsonValues = uint64_t(1) << 20;

// A render fails (exit 2, no output) when more than this fraction of its samples was
// discarded (NaN, infinite, or beyond the film's fixed-point range): the image would
// be wrong, not noisy.
inline constexpr double kMaxDiscardedFraction = 0.5;

// File sizes, each named in its error message. JSON is parsed into a DOM of about 20x
// its size at worst, OBJ meshes into index arrays of about 5x.
inline constexpr uint64_t kMaxSceneJsonBytes = uint64_t(64) << 20;   // JSON scene files
inline constexpr uint64_t kMaxMeshBytes = uint64_t(256) << 20;       // OBJ files, and all of one scene's OBJ files together
inline constexpr uint64_t kMaxMtlBytes = uint64_t(16) << 20;         // MTL material libraries
inline constexpr uint64_t kMaxBenchJsonBytes = uint64_t(64) << 20;   // compare's benchmark JSON files
inline constexpr uint64_t kMaxImageBytes = uint64_t(1) << 30;        // reference images (.pfm)

// Render sizes (RenderSettings::validate; `pathbench render`, bench, accuracy, crosscheck
// and the Python module all validate through it). Every product is formed in 64 bits
// from 32-bit factors, so none can wrap before it is compared.
// Pixels in one image: 2^28 is 16384 x 16384, whose film (28 bytes a pixel, 52 with
// variance) and float image (12 more) take 10 to 17 GB.
inline constexpr uint64_t kMaxPixels = uint64_t(1) << 28;
// Samples in one frame (pixels x spp): 2^48 keeps the 64-bit ray, path and sample
// counters far from wrapping at any path length (2^48 x 2^15 rays < 2^64), and is
// days of tracing at 10^9 samples/s.
inline constexpr uint64_t kMaxFrameSamples = uint64_t(1) << 48;
// Paths the ray-parallel strategy keeps in flight (--paths-in-flight): the GPU indexes
// its pool with 32 bits.
inline constexpr uint64_t kMaxPathsInFlight = 0xFFFFFFFFull;
// Host bytes a pixel costs a render: the film's sums and count (3 x 8 + 4), the float
// image made from them (3 x 4); with variance 3 x 8 sums of squares and a float image more.
inline constexpr uint64_t kFilmBytesPerPixel = 3 * 8 + 4 + 3 * 4;
inline constexpr uint64_t kVarianceBytesPerPixel = 3 * 8 + 3 * 4;

}  // namespace pb::limits
