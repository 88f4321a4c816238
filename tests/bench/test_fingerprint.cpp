// The machine fingerprint (common/src/fingerprint*.cpp) against its Python twin
// (tools/machine.py) on this machine and on fixture machines (tests/data/machines/:
// an Intel Xeon with hyper-threads and AVX-512/AMX, and the 2-core AMD EPYC VM with
// 512 KiB L2 and no AVX-512 that the committed results/amd-epyc/ came from), and what
// machine_id does and does not depend on.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "pathbench/common/fingerprint.h"
#include "pathbench/common/report.h"

namespace {

namespace fs = std::filesystem;
const std::string kSource = PATHBENCH_SOURCE_DIR;
const std::string kMachines = kSource + "/tests/data/machines/";

nlohmann::json python_host(const std::string& root) {
  const std::string cmd = std::string(PATHBENCH_PYTHON) + " " + kSource + "/tools/machine.py --root " + root;
  std::FILE* p = popen(cmd.c_str(), "r");
  if (!p) return nullptr;
  std::string out;
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  return pclose(p) == 0 ? nlohmann::json::parse(out) : nlohmann::json(nullptr);
}

// A copy of a fixture machine to change one file in.
std::string copy_machine(const std::string& name, const std::string& as) {
  const fs::path dst = fs::path(PATHBENCH_TEST_TMP) / as;
  fs::remove_all(dst);
  fs::copy(kMachines + name, dst, fs::copy_options::recursive);
  return dst.string();
}

TEST(Fingerprint, SameAsPythonTwin) {
  for (const std::string root : {std::string("/"), kMachines + "xeon-8480-ht", kMachines + "amd-epyc-zen3-vm"}) {
    const nlohmann::json cpp = pb::host_fingerprint(root);
    const nlohmann::json py = python_host(root);
    ASSERT_FALSE(py.is_null()) << "tools/machine.py --root " << root << " failed";
    EXPECT_EQ(cpp["cpu"], py["cpu"]) << root;
    EXPECT_EQ(cpp["memory_gib"], py["memory_gib"]) << root;
    EXPECT_EQ(cpp["memory_bytes"], py["memory_bytes"]) << root;
    EXPECT_EQ(cpp["machine_id"], py["machine_id"]) << root;
    EXPECT_EQ(cpp["machine_id"].get<std::string>().size(), 16u);
  }
}

TEST(Fingerprint, ReadsTheFixtureMachine) {
  const nlohmann::json x = pb::host_fingerprint(kMachines + "xeon-8480-ht");
  EXPECT_EQ(x["cpu"]["vendor"], "GenuineIntel");
  EXPECT_EQ(x["cpu"]["family"], 6);
  EXPECT_EQ(x["cpu"]["model"], 143);
  EXPECT_EQ(x["cpu"]["stepping"], 8);
  EXPECT_EQ(x["cpu"]["logical_cpus"], 4);
  EXPECT_EQ(x["cpu"]["physical_cores"], 2);
  EXPECT_EQ(x["cpu"]["max_mhz"], 3800);
  EXPECT_EQ(x["cpu"]["caches"]["L2"], 2 * 1024 * 1024);
  EXPECT_EQ(x["cpu"]["caches"]["L1d"], 48 * 1024);
  EXPECT_EQ(x["cpu"]["hypervisor"], false);
  EXPECT_NE(std::find(x["cpu"]["isa"].begin(), x["cpu"]["isa"].end(), "amx_tile"), x["cpu"]["isa"].end());
  EXPECT_EQ(x["clock"]["governor"], "performance");
  EXPECT_DOUBLE_EQ(x["clock"]["current_mhz"].get<double>(), 2001.0);
  EXPECT_EQ(x["memory_gib"], 63);
  const nlohmann::json a = pb::host_fingerprint(kMachines + "amd-epyc-zen3-vm");
  EXPECT_EQ(a["cpu"]["hypervisor"], true);
  EXPECT_EQ(a["cpu"]["max_mhz"], 0);  // no cpufreq in the VM
  EXPECT_TRUE(a["clock"]["governor"].is_null());
  EXPECT_DOUBLE_EQ(a["clock"]["current_mhz"].get<double>(), 2445.406);
}

TEST(Fingerprint, IdIgnoresClockAndLoadButNotHardware) {
  const std::string base = pb::host_fingerprint(kMachines + "xeon-8480-ht")["machine_id"];
  // The current clock and the governor are not identity.
  std::string r = copy_machine("xeon-8480-ht", "xeon-other-clock");
  std::ofstream(r + "/sys/devices/system/cpu/cpu0/cpufreq/scaling_cur_freq") << "3700000\n";
  std::ofstream(r + "/sys/devices/system/cpu/cpu0/cpufreq/scaling_governor") << "powersave\n";
  EXPECT_EQ(pb::host_fingerprint(r)["machine_id"], base);
  // A few MB less memory (kernel reserve) is the same machine; another L2 is not.
  r = copy_machine("xeon-8480-ht", "xeon-other-l2");
  std::ofstream(r + "/proc/meminfo") << "MemTotal:       65700000 kB\n";
  EXPECT_EQ(pb::host_fingerprint(r)["machine_id"], base);
  std::ofstream(r + "/sys/devices/system/cpu/cpu0/cache/index2/size") << "1024K\n";
  EXPECT_NE(pb::host_fingerprint(r)["machine_id"], base);
  // Two hosts both slugged "amd-epyc" are told apart when their hardware differs.
  const nlohmann::json vm = pb::host_fingerprint(kMachines + "amd-epyc-zen3-vm");
  EXPECT_EQ(pb::machine_identity_text(vm).find("model_name=AMD EPYC\n") != std::string::npos, true);
  EXPECT_NE(vm["machine_id"], base);
}

TEST(Fingerprint, ProcessFingerprintHasEverySection) {
  const nlohmann::json& fp = pb::machine_fingerprint();
  for (const char* k : {"schema", "machine_id", "cpu", "clock", "memory_bytes", "os", "build", "libraries"})
    EXPECT_TRUE(fp.contains(k)) << k;
  EXPECT_EQ(fp["machine_id"], pb::host_fingerprint("/")["machine_id"]);
  EXPECT_EQ(fp["build"]["git_revision"], pb::git_revision());
  EXPECT_FALSE(fp["build"]["cxx_flags"].get<std::string>().empty());
  EXPECT_GT(pb::process_cpu_seconds(), 0.0);
}

TEST(Slug, OneRule) {
  EXPECT_EQ(pb::slugify("AMD EPYC 7B13 64-Core Processor", "x"), "amd-epyc-7b13-64-core-processor");
  EXPECT_EQ(pb::slugify("NVIDIA H100 80GB HBM3", "x"), "nvidia-h100-80gb-hbm3");
  EXPECT_EQ(pb::slugify("cornell-box:mirror", "x"), "cornell-box-mirror");
  EXPECT_EQ(pb::slugify("  --  ", "scene"), "scene");
  EXPECT_EQ(pb::slugify("caf\xc3\xa9 GPU", "x"), "caf-gpu");  // non-ASCII bytes are separators
}

}  // namespace
