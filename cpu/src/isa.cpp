#include "pathbench/cpu/isa.h"

#include <fmt/format.h>

#include "pathbench/common/errors.h"

namespace pb::cpu {

namespace {
bool has_avx512() {
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
         __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
}
// The AVX2 path step fuses multiply-adds (shade_avx2.cpp's target has "fma"); every
// x86-64 CPU with AVX2 has FMA, but a virtual machine may hide one of them.
bool has_avx2() { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); }
}  // namespace

bool cpu_supports(Isa isa) {
  switch (isa) {
    case Isa::Avx512: return has_avx512();
    case Isa::Avx2: return has_avx2();
    case Isa::Auto:
    case Isa::Scalar: return true;
  }
  return false;
}

Isa resolve_isa(Isa asked) {
  if (asked == Isa::Auto) return has_avx512() ? Isa::Avx512 : has_avx2() ? Isa::Avx2 : Isa::Scalar;
  if (!cpu_supports(asked))
    throw InputError(fmt::format("--isa {}: this CPU lacks it (needs {}; it has: {})", to_string(asked),
                                 asked == Isa::Avx512 ? "avx512f, avx512bw, avx512dq and avx512vl" : "avx2 and fma",
                                 fmt::join(cpu_vector_flags(), ", ")));
  return asked;
}

int isa_lanes(Isa isa) { return isa == Isa::Avx512 ? 16 : isa == Isa::Avx2 ? 8 : 1; }

std::vector<std::string> cpu_vector_flags() {
  std::vector<std::string> out;
#define PB_FLAG(name) \
  if (__builtin_cpu_supports(name)) out.emplace_back(name);
  PB_FLAG("sse4.2") PB_FLAG("avx") PB_FLAG("avx2") PB_FLAG("fma") PB_FLAG("avx512f") PB_FLAG("avx512bw")
  PB_FLAG("avx512dq") PB_FLAG("avx512vl") PB_FLAG("avx512cd")
#undef PB_FLAG
  if (out.empty()) out.emplace_back("none beyond the x86-64 baseline");
  return out;
}

}  // namespace pb::cpu
