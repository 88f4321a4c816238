// The host half of the fingerprint: /proc/cpuinfo, /proc/meminfo and sysfs, read
// below a root so that tests can describe other machines. tools/machine.py reads the
// same files the same way; keep the two in step (tests/python/test_fingerprint.py
// checks that they agree, on this machine and on fixture trees).
#include <fmt/core.h>

#include <cstdint>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "pathbench/common/fingerprint.h"

namespace pb {

namespace {

// The instruction-set extensions that decide which code paths pathbench, Embree and
// the compiler can use here, in a fixed order (the identity text lists them so).
const char* const kIsaFlags[] = {"sse2",     "sse4_1",   "sse4_2",   "avx",         "avx2",        "fma",
                                 "f16c",     "bmi2",     "avx512f",  "avx512dq",    "avx512cd",    "avx512bw",
                                 "avx512vl", "avx512ifma", "avx512vbmi", "avx512_vnni", "avx512_bf16", "amx_tile"};

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  const size_t b = s.find_last_not_of(" \t\r\n");
  return s.substr(a, b - a + 1);
}

std::string first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return trim(line);
}

long long to_int(const std::string& s, long long fallback) {
  try {
    size_t used = 0;
    const long long v = std::stoll(s, &used);
    return used == s.size() ? v : fallback;
  } catch (...) {
    return fallback;
  }
}

double to_double(const std::string& s, double fallback) {
  try {
    return std::stod(s);
  } catch (...) {
    return fallback;
  }
}

// "32K", "1024K", "32M" -> bytes; -1 when unreadable.
long long size_bytes(const std::string& s) {
  if (s.empty()) return -1;
  long long mult = 1;
  std::string digits = s;
  switch (s.back()) {
    case 'K': mult = 1024; digits.pop_back(); break;
    case 'M': mult = 1024 * 1024; digits.pop_back(); break;
    case 'G': mult = 1024LL * 1024 * 1024; digits.pop_back(); break;
    default: break;
  }
  const long long v = to_int(digits, -1);
  return v < 0 ? -1 : v * mult;
}

struct CpuInfo {
  std::map<std::string, std::string> first;  // fields of the first processor block
  int logical = 0;
  std::set<std::pair<std::string, std::string>> cores;  // (physical id, core id)
  std::set<std::string> sockets;
};

CpuInfo read_cpuinfo(const std::string& path) {
  CpuInfo info;
  std::ifstream in(path);
  std::string line, physical;
  while (std::getline(in, line)) {
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = trim(line.substr(0, colon)), value = trim(line.substr(colon + 1));
    if (key == "processor") ++info.logical;
    if (info.logical <= 1 && !info.first.count(key)) info.first[key] = value;
    if (key == "physical id") {
      physical = value;
      info.sockets.insert(value);
    }
    if (key == "core id") info.cores.insert({physical, value});
  }
  return info;
}

}  // namespace

nlohmann::json host_fingerprint(const std::string& root_in) {
  std::string root = root_in.empty() ? "/" : root_in;
  if (root.back() != '/') root += '/';
  const CpuInfo ci = read_cpuinfo(root + "proc/cpuinfo");
  auto field = [&](const char* k) {
    auto it = ci.first.find(k);
    return it == ci.first.end() ? std::string() : it->second;
  };
  std::set<std::string> flags;
  {
    std::istringstream ss(field("flags"));
    for (std::string f; ss >> f;) flags.insert(f);
  }
  nlohmann::json isa = nlohmann::json::array();
  for (const char* f : kIsaFlags)
    if (flags.count(f)) isa.push_back(f);

  const std::string cpu0 = root + "sys/devices/system/cpu/cpu0/";
  nlohmann::json caches = nlohmann::json::object();
  for (int i = 0; i < 10; ++i) {
    const std::string dir = fmt::format("{}cache/index{}/", cpu0, i);
    const std::string level = first_line(dir + "level"), type = first_line(dir + "type");
    const long long bytes = size_bytes(first_line(dir + "size"));
    if (level.empty() || bytes < 0) continue;
    const std::string suffix = type == "Data" ? "d" : type == "Instruction" ? "i" : "";
    caches["L" + level + suffix] = bytes;
  }
  const long long max_khz = to_int(first_line(cpu0 + "cpufreq/cpuinfo_max_freq"), 0);

  nlohmann::json cpu;
  cpu["vendor"] = field("vendor_id").empty() ? "unknown" : field("vendor_id");
  cpu["model_name"] = field("model name").empty() ? "unknown CPU" : field("model name");
  cpu["family"] = to_int(field("cpu family"), -1);
  cpu["model"] = to_int(field("model"), -1);
  cpu["stepping"] = to_int(field("stepping"), -1);
  cpu["logical_cpus"] = ci.logical;
  cpu["physical_cores"] = ci.cores.empty() ? ci.logical : int(ci.cores.size());
  cpu["sockets"] = ci.sockets.empty() ? 1 : int(ci.sockets.size());
  cpu["isa"] = isa;
  cpu["hypervisor"] = flags.count("hypervisor") > 0;
  cpu["max_mhz"] = max_khz / 1000;  // 0: not readable (typical in VMs)
  cpu["caches"] = caches;

  // Volatile: where the clock is now and who sets it. Never part of machine_id.
  nlohmann::json clock;
  const long long cur_khz = to_int(first_line(cpu0 + "cpufreq/scaling_cur_freq"), 0);
  if (cur_khz > 0) clock["current_mhz"] = double(cur_khz) / 1000.0;
  else if (to_double(field("cpu MHz"), 0) > 0) clock["current_mhz"] = to_double(field("cpu MHz"), 0);
  const std::string governor = first_line(cpu0 + "cpufreq/scaling_governor");
  clock["governor"] = governor.empty() ? nlohmann::json(nullptr) : nlohmann::json(governor);
  const long long min_khz = to_int(first_line(cpu0 + "cpufreq/cpuinfo_min_freq"), 0);
  if (min_khz > 0) clock["min_mhz"] = min_khz / 1000;
  const std::string boost = first_line(root + "sys/devices/system/cpu/cpufreq/boost");
  if (!boost.empty()) clock["boost"] = boost == "1";

  long long mem_kb = 0;
  {
    std::ifstream in(root + "proc/meminfo");
    std::string key;
    long long v = 0;
    while (in >> key >> v) {
      if (key == "MemTotal:") {
        mem_kb = v;
        break;
      }
      in.ignore(1 << 20, '\n');
    }
  }
  nlohmann::json j;
  j["cpu"] = cpu;
  j["memory_bytes"] = uint64_t(mem_kb) * 1024;
  j["memory_gib"] = (mem_kb + 524288) / 1048576;  // rounded, so a few MB of kernel reserve do not matter
  j["clock"] = clock;
  j["machine_id"] = fnv1a64_hex(machine_identity_text(j));
  return j;
}

std::string machine_identity_text(const nlohmann::json& host) {
  const nlohmann::json& c = host.at("cpu");
  std::string isa, caches;
  for (const auto& f : c.at("isa")) isa += (isa.empty() ? "" : ",") + f.get<std::string>();
  for (const auto& [k, v] : c.at("caches").items())  // nlohmann's object keys are sorted
    caches += fmt::format("{}{}:{}", caches.empty() ? "" : ",", k, v.get<long long>());
  return fmt::format(
      "vendor={}\nmodel_name={}\nfamily={}\nmodel={}\nstepping={}\nlogical_cpus={}\nphysical_cores={}\nsockets={}\n"
      "isa={}\nhypervisor={}\nmax_mhz={}\ncaches={}\nmemory_gib={}\n",
      c.at("vendor").get<std::string>(), c.at("model_name").get<std::string>(), c.at("family").get<long long>(),
      c.at("model").get<long long>(), c.at("stepping").get<long long>(), c.at("logical_cpus").get<int>(),
      c.at("physical_cores").get<int>(), c.at("sockets").get<int>(), isa, c.at("hypervisor").get<bool>() ? 1 : 0,
      c.at("max_mhz").get<long long>(), caches, host.at("memory_gib").get<long long>());
}

std::string fnv1a64_hex(std::string_view text) {
  uint64_t h = 1469598103934665603ULL;
  for (unsigned char ch : text) {
    h ^= ch;
    h *= 1099511628211ULL;
  }
  return fmt::format("{:016x}", h);
}

}  // namespace pb
