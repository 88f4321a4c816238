#pragma once
// Preset `loading`: scene-file loading time against the number of placed meshes
// (issue 34: loading is linear in placements and list lengths). One load_scene of a
// generated file per iteration (written once to a temporary folder, outside the
// timing; read from the page cache), named load/<format>/<what>:<N>:
//   load/gltf/placements:N    a 1-triangle mesh placed N times through two levels of
//                             shared nodes (a root naming a node N/1000 times, which
//                             names the mesh's node 1000 times): a tiny file, N
//                             placements (10^5 .. 10^6)
//   load/json/instances:N     a JSON scene with one OBJ quad and an "instances" list
//                             of N transforms (10^5 .. 10^6)
//   load/mitsuba/spheres:N    N Mitsuba <shape type="sphere">s (4,096 triangles each)
// Each family is fitted to O(N) by Google Benchmark (its _BigO and _RMS rows: a
// small RMS says the time is linear in N). Counters: placements_per_second
// (kIsRate), triangles, file_bytes.
namespace pb::bench {

void preset_loading();

}  // namespace pb::bench
