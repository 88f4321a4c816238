#include "pathbench/cpu/embree_facts.h"

#include <embree3/rtcore.h>
#include <fmt/core.h>
#include <tbb/task_arena.h>
#include <tbb/version.h>

#include "pathbench/common/fingerprint.h"

namespace pb::cpu {

namespace {

// Embree 3 does not name the ISA it dispatched to, but its native packet widths are
// answered at run time from the ISAs compiled into the library and present on the CPU
// (16 wide: AVX-512, 8 wide: AVX/AVX2, 4 wide: SSE); AVX against AVX2 is then the CPU's
// avx2 flag (Debian's Embree is built for both). Hence "isa_derived".
std::string derived_isa(RTCDevice d) {
  if (rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) return "avx512";
  if (rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED)) {
    for (const auto& f : machine_fingerprint()["cpu"]["isa"])
      if (f == "avx2") return "avx2";
    return "avx";
  }
  if (rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED)) return "sse";
  return "unknown";
}

nlohmann::json compute() {
  nlohmann::json j;
  nlohmann::json e;
  e["version_compiled"] = RTC_VERSION_STRING;
  if (RTCDevice d = rtcNewDevice(nullptr)) {
    e["version"] = fmt::format("{}.{}.{}", rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_VERSION_MAJOR),
                               rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_VERSION_MINOR),
                               rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_VERSION_PATCH));
    e["isa_derived"] = derived_isa(d);
    e["native_packet_widths"] = nlohmann::json::array();
    for (auto [w, p] : {std::pair{4, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED},
                        std::pair{8, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED},
                        std::pair{16, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED}})
      if (rtcGetDeviceProperty(d, p)) e["native_packet_widths"].push_back(w);
    const auto tasking = rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_TASKING_SYSTEM);
    e["tasking"] = tasking == 0 ? "internal" : tasking == 1 ? "tbb" : tasking == 2 ? "ppl" : "unknown";
    rtcReleaseDevice(d);
  }
  j["embree"] = e;
  j["tbb"] = {{"version_compiled", TBB_VERSION_STRING},
              {"version", TBB_runtime_version()},
              {"max_concurrency", tbb::this_task_arena::max_concurrency()}};
  return j;
}

}  // namespace

const nlohmann::json& embree_tbb_facts() {
  static const nlohmann::json facts = compute();
  return facts;
}

}  // namespace pb::cpu
