#pragma once
// The machine fingerprint every JSON pathbench writes carries (bench JSON
// `context.fingerprint`, render reports' `fingerprint`, reproduce/accuracy JSON): one
// object describing the host (CPU, ISA, caches, clocks, memory, kernel), the build
// (compiler, flags, ISA compiled for, git revision) and the libraries. `machine_id`
// hashes only the identity fields (hardware that does not change between runs: not
// load, not the current clock, not software), so two runs share it exactly when they
// ran on the same kind of host. tools/machine.py computes the same id in Python.
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace pb {

// Host facts read below `root` ("/" in real use; tests point it at a fixture tree with
// proc/cpuinfo, proc/meminfo and sys/devices/system/cpu/cpu0/...). Has "cpu",
// "memory_bytes", "memory_gib", "clock" and "machine_id"; nothing from the build.
nlohmann::json host_fingerprint(const std::string& root = "/");

// The canonical text `machine_id` hashes: "key=value" lines in a fixed order, built
// from a host_fingerprint()'s identity fields.
std::string machine_identity_text(const nlohmann::json& host);
// 64-bit FNV-1a of `text` as 16 lowercase hex digits (the same in tools/machine.py).
std::string fnv1a64_hex(std::string_view text);

// This process's fingerprint: host_fingerprint("/") plus "os" (uname), "build"
// (compiler, flags, build type, ISA compiled for, git revision) and "libraries"
// (versions compiled against). Computed once per process; schema in docs/reference.md, "Machine fingerprint".
// Tracers add their own sections ("embree", "gpu") through pb::run::run_fingerprint (run/run_context.h).
const nlohmann::json& machine_fingerprint();

// /proc/loadavg's first three numbers, or null where unreadable.
nlohmann::json load_average();
// CPU time (user + system) this process has used, in seconds.
double process_cpu_seconds();

// The one slug rule of the project: lowercase ASCII letters and digits kept, every
// other run of characters one '-', none at either end; `fallback` when nothing is left.
// (results/<machine>/ folder names, file stems.) tools/machine.py has its twin.
std::string slugify(std::string_view text, std::string_view fallback);

}  // namespace pb
