#pragma once
// Preset `materials`: what modelling only what a scene requires buys. Render
// benchmarks (render_bench.h names and counters: rays_per_second,
// state_bytes_per_path, ...) of diffuse-only scenes and of the cornell-box variants
// with mirrors, glass and rough metal, both strategies of every device. The diffuse
// scenes run the path step's diffuse-only instantiation, the others the one with
// every kind (features.h). tools/feature_specialisation.py runs the paper-cornell rows
// here in a normal and a -DPATHBENCH_EXTRA_MATERIALS=OFF build and compares them.
namespace pb::bench {

void preset_materials();

}  // namespace pb::bench
