#pragma once
// The CPU tracer's part of the machine fingerprint: Embree's version and the ISA it
// chose on this CPU, TBB's runtime version and thread count.
#include <nlohmann/json.hpp>

namespace pb::cpu {

// {"embree": {...}, "tbb": {...}}; computed once per process (creates one Embree device).
const nlohmann::json& embree_tbb_facts();

}  // namespace pb::cpu
