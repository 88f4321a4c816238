#include "compare_context.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace pb::analysis {

namespace {

using Json = nlohmann::json;

// "a.b.c" -> compact value text, for every leaf under `j`.
void flatten(const Json& j, const std::string& prefix, std::map<std::string, std::string>& out) {
  if (j.is_object()) {
    for (const auto& [k, v] : j.items()) flatten(v, prefix.empty() ? k : prefix + "." + k, out);
    return;
  }
  out[prefix] = j.is_string() ? j.get<std::string>() : j.dump();
}

// The keys whose values differ between a and b (missing on one side counts), at most
// `limit` of them as "key: a -> b".
std::vector<std::string> differences(const Json& a, const Json& b, size_t limit = 6) {
  std::map<std::string, std::string> fa, fb;
  flatten(a, "", fa);
  flatten(b, "", fb);
  std::vector<std::string> out;
  for (const auto& [k, v] : fa) {
    auto it = fb.find(k);
    const std::string w = it == fb.end() ? "(none)" : it->second;
    if (v != w) out.push_back(fmt::format("{}: {} -> {}", k, v, w));
  }
  for (const auto& [k, v] : fb)
    if (!fa.count(k)) out.push_back(fmt::format("{}: (none) -> {}", k, v));
  if (out.size() > limit) {
    const size_t more = out.size() - limit;
    out.resize(limit);
    out.push_back(fmt::format("... {} more", more));
  }
  return out;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : "; ") + x;
  return s;
}

const Json* fingerprint_of(const BenchFile& f) {
  auto it = f.context.find("fingerprint");
  return it != f.context.end() && it->is_object() ? &*it : nullptr;
}

Json pick(const Json& j, std::initializer_list<const char*> keys) {
  Json out = Json::object();
  for (const char* k : keys)
    if (j.contains(k)) out[k] = j[k];
  return out;
}

// Google Benchmark's context with its caches array as {"L1d": bytes, ...}, so that a
// difference reads "caches.L2: 524288 -> 1048576".
Json gb_machine(const Json& context) {
  Json out = pick(context, {"cpu_model", "num_cpus", "mhz_per_cpu"});
  if (context.contains("caches") && context["caches"].is_array()) {
    Json caches = Json::object();
    for (const auto& c : context["caches"]) {
      const std::string type = c.value("type", std::string());
      caches[fmt::format("L{}{}", c.value("level", 0), type == "Data" ? "d" : type == "Instruction" ? "i" : "")] =
          c.value("size", Json(nullptr));
    }
    out["caches"] = caches;
  }
  return out;
}

Json run_summary(const BenchFile& f) {
  const Json* fp = fingerprint_of(f);
  const Json& c = f.context;
  return {{"path", f.path},
          {"git_revision", c.value("git_revision", std::string("unknown"))},
          {"date", c.value("date_utc", c.value("date", std::string("?")))},
          {"machine", c.value("machine", std::string("?"))},
          {"machine_id", fp ? (*fp)["machine_id"] : Json(nullptr)},
          {"load_average_at_start", c.contains("load_avg") ? c["load_avg"] : Json(nullptr)},
          {"cpu_per_wall", c.contains("run") ? c["run"].value("cpu_per_wall", Json(nullptr)) : Json(nullptr)}};
}

void check_machine(const BenchFile& a, const BenchFile& b, CompareReport& rep) {
  const Json *fa = fingerprint_of(a), *fb = fingerprint_of(b);
  if (fa && fb) {
    if ((*fa)["machine_id"] != (*fb)["machine_id"])
      rep.warnings.push_back(fmt::format(
          "different machine: machine_id {} -> {} ({})", (*fa)["machine_id"].dump(), (*fb)["machine_id"].dump(),
          joined(differences(pick(*fa, {"cpu", "memory_gib"}), pick(*fb, {"cpu", "memory_gib"})))));
    const Json ga = fa->value("gpu", Json::object()), gb = fb->value("gpu", Json::object());
    if (ga.value("gpu_id", Json(nullptr)) != gb.value("gpu_id", Json(nullptr)))
      rep.warnings.push_back(fmt::format("different GPU: {} -> {}", ga.value("name", ga.value("none", std::string("none"))),
                                         gb.value("name", gb.value("none", std::string("none")))));
    const auto build = differences(pick(*fa, {"build", "libraries"}), pick(*fb, {"build", "libraries"}));
    std::vector<std::string> real;  // the revision differing is the point of comparing
    for (const auto& d : build)
      if (d.rfind("build.git_revision", 0) != 0 && d.rfind("build.source_commit", 0) != 0) real.push_back(d);
    if (!real.empty()) rep.warnings.push_back("different build: " + joined(real));
    return;
  }
  for (const BenchFile* f : {&a, &b})
    if (!fingerprint_of(*f))
      rep.notes.push_back(fmt::format("{} has no machine fingerprint (written before pathbench had one): the machine "
                                      "is judged by Google Benchmark's CPU facts only",
                                      f->path));
  const auto cpu = differences(gb_machine(a.context), gb_machine(b.context));
  if (!cpu.empty()) rep.warnings.push_back("different machine: " + joined(cpu));
  const auto build = differences(pick(a.context, {"compiler", "cxx_flags", "build_type", "embree_version"}),
                                 pick(b.context, {"compiler", "cxx_flags", "build_type", "embree_version"}));
  if (!build.empty()) rep.warnings.push_back("different build: " + joined(build));
}

void check_settings(const BenchFile& a, const BenchFile& b, CompareReport& rep) {
  std::vector<std::string> d = differences(pick(a.context, {"pathbench_preset", "cpu_tbb_threads"}),
                                           pick(b.context, {"pathbench_preset", "cpu_tbb_threads"}));
  std::vector<std::string> layouts;
  int unlabelled = 0;
  for (const auto& name : a.order) {
    auto it = b.series.find(name);
    if (it == b.series.end()) continue;
    const BenchSeries &x = a.series.at(name), &y = it->second;
    if (x.cpu_threads >= 0 && y.cpu_threads >= 0 && x.cpu_threads != y.cpu_threads)
      d.push_back(fmt::format("{}: threads {} -> {}", name, x.cpu_threads, y.cpu_threads));
    auto layout = [](const BenchSeries& s) {
      std::string out;
      for (const auto& l : s.labels)
        if (l.rfind("embree_layout=", 0) == 0) out += (out.empty() ? "" : ",") + l.substr(14);
      return out;
    };
    if (layout(x).empty() != layout(y).empty()) ++unlabelled;
    else if (layout(x) != layout(y)) layouts.push_back(fmt::format("{}: {} -> {}", name, layout(x), layout(y)));
  }
  if (unlabelled)  // files from before the label: unknown is not a difference
    rep.notes.push_back(fmt::format("{} benchmark(s) name their Embree layout in one file only", unlabelled));
  if (!d.empty()) rep.warnings.push_back("different settings: " + joined(d));
  if (!layouts.empty())
    rep.warnings.push_back(fmt::format("different Embree layout in {} benchmark(s): {}", layouts.size(),
                                       joined(layouts)));
}

// Load: the 1-minute load average at the start (Google Benchmark's load_avg), and the
// run's process CPU time over wall time where the file has it (context.run).
void check_load(const BenchFile& a, const BenchFile& b, CompareReport& rep) {
  auto load1 = [](const BenchFile& f) {
    const Json& l = f.context.value("load_avg", Json::array());
    return l.is_array() && !l.empty() && l[0].is_number() ? l[0].get<double>() : -1.0;
  };
  const double la = load1(a), lb = load1(b);
  const double cpus = std::max(1.0, double(b.context.value("num_cpus", a.context.value("num_cpus", 1))));
  if (la >= 0 && lb >= 0) {
    if (std::fabs(la - lb) > std::max(0.5, 0.25 * cpus))
      rep.warnings.push_back(fmt::format("different load: 1-minute load average at the start {:.2f} -> {:.2f} on {} "
                                         "CPUs (another process was running)",
                                         la, lb, cpus));
    else if (std::max(la, lb) > 0.5 * cpus)
      rep.notes.push_back(fmt::format("both runs started on a busy machine (load {:.2f} and {:.2f} on {} CPUs)", la,
                                      lb, cpus));
  }
  auto cpw = [](const BenchFile& f) {
    return f.context.contains("run") && f.context["run"].value("cpu_per_wall", Json(nullptr)).is_number()
               ? f.context["run"]["cpu_per_wall"].get<double>()
               : -1.0;
  };
  const double ca = cpw(a), cb = cpw(b);
  if (ca > 0 && cb > 0 && std::fabs(cb / ca - 1) > 0.2)
    rep.warnings.push_back(fmt::format("different CPU share: the process used {:.2f} -> {:.2f} CPU seconds per wall "
                                       "second over the whole run",
                                       ca, cb));
}

}  // namespace

void describe_runs(const BenchFile& base, const BenchFile& next, CompareReport& rep) {
  rep.base_run = run_summary(base);
  rep.new_run = run_summary(next);
  check_machine(base, next, rep);
  check_settings(base, next, rep);
  check_load(base, next, rep);
  const int contended = count_verdict(rep.rows, Verdict::Contended);
  if (contended)
    rep.warnings.push_back(fmt::format("{} benchmark(s) contended: wall time up, CPU time flat; rerun on a quiet "
                                       "machine before trusting their times",
                                       contended));
  const int invalid = count_verdict(rep.rows, Verdict::Invalid);
  if (invalid) rep.warnings.push_back(fmt::format("{} benchmark(s) with a zero median time: not compared", invalid));
}

}  // namespace pb::analysis
