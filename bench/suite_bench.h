#pragma once
// The suite's benchmarks (`pathbench suite`, tools/suite): the Python orchestrator writes
// the cases of one device into a JSON file and runs
//   pathbench-bench --preset suite --suite-cases FILE [--benchmark_* options]
// FILE: {"suite": "pathbench", "version": 1, "mode": "quick"|"full", "manifest_sha256": "...",
//        "device_label": "cpu"|"gpu"|..., "cases": [{"name": "suite/<workload>/<device>/<strategy>",
//        "scene": built-in name or path, "device": "cpu"|"gpu", "iterations": 0,
//        "settings": {width, height, spp, bounces, sampling, strategy, isa, instancing,
//                     precision, embree_layout, seed, converged}}]}
// Each case is a render benchmark (render_bench.h: time, rays/s, memory, energy, clocks) whose
// scene is built once on its device (RenderCase::build_once: the counter build_seconds).
#include <string>

namespace pb::bench {

// Registers the cases and adds suite, suite_version, suite_mode, suite_manifest_sha256 and
// suite_device to the context. Returns the preset the JSON names (context.pathbench_preset,
// which keys the history's series): "suite", or "suite-quick" for mode quick. Throws
// std::runtime_error naming the file and field.
std::string preset_suite(const std::string& cases_path);

}  // namespace pb::bench
