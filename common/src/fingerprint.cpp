// The process half of the fingerprint: kernel, build and library facts, load and CPU
// time, and the project's one slug rule. Host facts: fingerprint_host.cpp.
#include "pathbench/common/fingerprint.h"

#include <fmt/core.h>
#include <sys/resource.h>
#include <sys/utsname.h>

#include <cctype>
#include <cstdlib>
#include <fstream>

#include "pathbench/common/report.h"

#if PATHBENCH_HAVE_OIIO
#include <OpenImageIO/oiioversion.h>
#endif

#ifndef PATHBENCH_CXX_FLAGS
#define PATHBENCH_CXX_FLAGS "unknown"
#endif
#ifndef PATHBENCH_CMAKE_COMPILER
#define PATHBENCH_CMAKE_COMPILER "unknown"
#endif
#ifndef PATHBENCH_BUILD_TYPE
#define PATHBENCH_BUILD_TYPE "unknown"
#endif

namespace pb {

namespace {

// The instruction sets this translation unit was compiled for (the project's common
// flags, -march=native with PATHBENCH_NATIVE): what the build may use, beside what the
// CPU offers (cpu.isa).
nlohmann::json isa_compiled() {
  nlohmann::json a = nlohmann::json::array();
#ifdef __SSE2__
  a.push_back("sse2");
#endif
#ifdef __SSE4_2__
  a.push_back("sse4_2");
#endif
#ifdef __AVX__
  a.push_back("avx");
#endif
#ifdef __AVX2__
  a.push_back("avx2");
#endif
#ifdef __FMA__
  a.push_back("fma");
#endif
#ifdef __AVX512F__
  a.push_back("avx512f");
#endif
#ifdef __AVX512BW__
  a.push_back("avx512bw");
#endif
#ifdef __AVX512VL__
  a.push_back("avx512vl");
#endif
#ifdef __aarch64__
  a.push_back("aarch64");
#endif
  return a;
}

nlohmann::json build_facts() {
  nlohmann::json b;
  b["compiler"] = compiler_id();
  b["cmake_compiler"] = PATHBENCH_CMAKE_COMPILER;  // CMake's id and version, e.g. "GNU 12.2.0"
  b["cxx_flags"] = PATHBENCH_CXX_FLAGS;
  b["build_type"] = PATHBENCH_BUILD_TYPE;
  b["isa_compiled"] = isa_compiled();
  b["git_revision"] = git_revision();
  // A copy of the tree without .git (a GPU host) has no revision of its own; the copier
  // may name the source commit.
  if (const char* c = std::getenv("PATHBENCH_SOURCE_COMMIT"); c && *c) b["source_commit"] = c;
  return b;
}

nlohmann::json os_facts() {
  nlohmann::json o;
  struct utsname u {};
  if (uname(&u) == 0) {
    o["kernel"] = fmt::format("{} {}", u.sysname, u.release);
    o["kernel_version"] = u.version;
    o["arch"] = u.machine;
    o["hostname"] = u.nodename;
  }
  return o;
}

nlohmann::json library_facts() {
  nlohmann::json l;
  l["fmt"] = fmt::format("{}.{}.{}", FMT_VERSION / 10000, FMT_VERSION / 100 % 100, FMT_VERSION % 100);
  l["nlohmann_json"] = fmt::format("{}.{}.{}", NLOHMANN_JSON_VERSION_MAJOR, NLOHMANN_JSON_VERSION_MINOR,
                                   NLOHMANN_JSON_VERSION_PATCH);
#if PATHBENCH_HAVE_OIIO
  l["openimageio"] = OIIO_VERSION_STRING;
#else
  l["openimageio"] = nullptr;  // built without it
#endif
  return l;
}

}  // namespace

const nlohmann::json& machine_fingerprint() {
  static const nlohmann::json fp = [] {
    nlohmann::json j = host_fingerprint("/");
    j["schema"] = 1;
    j["os"] = os_facts();
    j["build"] = build_facts();
    j["libraries"] = library_facts();
    return j;
  }();
  return fp;
}

nlohmann::json load_average() {
  std::ifstream in("/proc/loadavg");
  double a = 0, b = 0, c = 0;
  if (!(in >> a >> b >> c)) return nullptr;
  return {a, b, c};
}

double process_cpu_seconds() {
  struct rusage ru {};
  if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
  auto sec = [](const timeval& t) { return double(t.tv_sec) + double(t.tv_usec) * 1e-6; };
  return sec(ru.ru_utime) + sec(ru.ru_stime);
}

std::string slugify(std::string_view text, std::string_view fallback) {
  std::string out;
  for (char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 128 && std::isalnum(u)) out += char(std::tolower(u));
    else if (!out.empty() && out.back() != '-') out += '-';
  }
  while (!out.empty() && out.back() == '-') out.pop_back();
  return out.empty() ? std::string(fallback) : out;
}

}  // namespace pb
