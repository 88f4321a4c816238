#pragma once
// What `pathbench compare` checks before trusting a comparison: whether the two runs
// ran on the same machine (fingerprint machine_id and identity fields, or Google
// Benchmark's CPU facts for files without a fingerprint), the same build (compiler,
// flags, libraries), the same settings (preset, threads), the same Embree layout per
// benchmark (labels "embree_layout=..."), and under similar load.
#include "pathbench/analysis/bench_compare.h"

namespace pb::analysis {

// What compare reads of a file's "context" (null: none), every field's type checked;
// throws InputError naming `path` and the field ("context.fingerprint.machine_id: ...").
BenchContext read_bench_context(const std::string& path, const nlohmann::json& context);

// Fills rep.base_run / new_run, rep.warnings and rep.notes.
void describe_runs(const BenchFile& base, const BenchFile& next, CompareReport& rep);

}  // namespace pb::analysis
