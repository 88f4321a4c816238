#pragma once
// Which instruction set the CPU tracer's batched path step runs (--isa): checked against
// the CPU at run time, so one build runs everywhere and uses the widest vectors there.
#include <string>
#include <vector>

#include "pathbench/common/settings.h"

namespace pb::cpu {

// Whether this CPU can run `isa` (Auto and Scalar: always). AVX-512 means the
// F, BW, DQ and VL subsets (what the 16-lane code and Embree's AVX-512 kernels use).
bool cpu_supports(Isa isa);
// Auto -> the widest the CPU supports; otherwise `asked`, or InputError naming --isa
// and the missing CPU flags.
Isa resolve_isa(Isa asked);
// Lanes of the batched path step for a resolved ISA (Scalar: 1).
int isa_lanes(Isa isa);
// The CPU's vector flags that matter here (for reports: "avx2", "avx512f", ...).
std::vector<std::string> cpu_vector_flags();

}  // namespace pb::cpu
