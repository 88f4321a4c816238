#include "compare_context.h"

#include <fmt/core.h>

#include <optional>

#include <algorithm>
#include <cmath>
#include <map>

#include "json_fields.h"
#include "pathbench/common/display_text.h"

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
    if (v != w) out.push_back(fmt::format("{}: {} -> {}", clip_text(k), clip_text(v), clip_text(w)));
  }
  for (const auto& [k, v] : fb)
    if (!fa.count(k)) out.push_back(fmt::format("{}: (none) -> {}", clip_text(k), clip_text(v)));
  if (out.size() > limit) {
    const size_t more = out.size() - limit;
    out.resize(limit);
    out.push_back(fmt::format("... {} more", more));
  }
  return out;
}

// The first `limit` items, each clipped, joined with "; " (then "... N more").
std::string joined(const std::vector<std::string>& v, size_t limit = 8) {
  std::string s;
  for (size_t i = 0; i < v.size() && i < limit; ++i) s += (s.empty() ? "" : "; ") + clip_text(v[i], 320);
  if (v.size() > limit) s += fmt::format("; ... {} more", v.size() - limit);
  return s;
}

Json pick(const Json& j, std::initializer_list<const char*> keys) {
  Json out = Json::object();
  for (const char* k : keys)
    if (const auto it = j.find(k); it != j.end()) out[k] = *it;
  return out;
}

// Google Benchmark's caches array as {"L1d": bytes, ...}, so that a difference reads
// "caches.L2: 524288 -> 1048576".
Json gb_caches(const fields::Reader& c) {
  const Json* caches = c.array("caches");
  if (!caches) return nullptr;
  Json out = Json::object();
  for (size_t i = 0; i < caches->size(); ++i) {
    const std::string name = fmt::format("{}[{}]", c.field("caches"), i);
    const Json& entry = (*caches)[i];
    if (!entry.is_object()) fields::wrong(c.path(), name, "an object", entry);
    const fields::Reader e = c.sub(entry, name);
    const std::string type = e.string_or("type", "");
    const int level = int(e.number("level", 0, 16, true).value_or(0));
    const Json* size = fields::member(entry, "size");
    out[fmt::format("L{}{}", level, type == "Data" ? "d" : type == "Instruction" ? "i" : "")] = size ? *size : Json();
  }
  return out;
}

}  // namespace

BenchContext read_bench_context(const std::string& path, const Json& context) {
  BenchContext r;
  if (context.is_null()) return r;
  if (!context.is_object()) fields::wrong(path, "context", "an object", context);
  const fields::Reader c(path, context, "context");
  r.git_revision = c.string_or("git_revision", "unknown");
  r.date = c.string("date_utc").value_or(c.string_or("date", "?"));
  r.machine = c.string_or("machine", "?");
  if (const Json* fp = c.object("fingerprint")) {
    const fields::Reader f = c.sub(*fp, c.field("fingerprint"));
    const std::optional<std::string> id = f.string("machine_id");
    if (!id || id->empty())
      throw InputError(fmt::format("{}: {}: missing or empty (a machine fingerprint names its machine)", path,
                                   f.field("machine_id")));
    r.has_fingerprint = true;
    r.machine_id = *id;
    r.identity = pick(*fp, {"cpu", "memory_gib"});
    r.build = pick(*fp, {"build", "libraries"});
    if (const Json* gpu = f.object("gpu")) {
      const fields::Reader g = f.sub(*gpu, f.field("gpu"));
      if (const auto gid = g.string("gpu_id")) r.gpu_id = *gid;
      r.gpu_name = g.string("name").value_or(g.string_or("none", "none"));
    }
  }
  r.gb_machine = pick(context, {"cpu_model", "num_cpus", "mhz_per_cpu"});
  if (Json caches = gb_caches(c); !caches.is_null()) r.gb_machine["caches"] = std::move(caches);
  r.gb_build = pick(context, {"compiler", "cxx_flags", "build_type", "embree_version"});
  r.settings = pick(context, {"pathbench_preset", "cpu_tbb_threads"});
  // 1 to 2^24 CPUs; loads and CPU shares up to 2^40 (anything larger is not a measurement).
  r.num_cpus = c.number("num_cpus", 1, double(1 << 24), true).value_or(-1);
  if (const Json* load = c.array("load_avg")) {
    r.load_avg = *load;
    for (size_t i = 0; i < load->size(); ++i)
      if (!(*load)[i].is_null()) c.number_value((*load)[i], fmt::format("{}[{}]", c.field("load_avg"), i), 0, 0x1p40);
    if (!load->empty() && !load->front().is_null()) r.load1 = load->front().get<double>();
  }
  if (const Json* run = c.object("run"))
    r.cpu_per_wall = c.sub(*run, c.field("run")).number("cpu_per_wall", 0, 0x1p40).value_or(-1);
  return r;
}

namespace {

Json run_summary(const BenchFile& f) {
  const BenchContext& c = f.run;
  return {{"path", f.path},
          {"git_revision", c.git_revision},
          {"date", c.date},
          {"machine", c.machine},
          {"machine_id", c.has_fingerprint ? Json(c.machine_id) : Json(nullptr)},
          {"load_average_at_start", c.load_avg},
          {"cpu_per_wall", c.cpu_per_wall >= 0 ? Json(c.cpu_per_wall) : Json(nullptr)}};
}

void check_machine(const BenchFile& a, const BenchFile& b, CompareReport& rep) {
  const BenchContext &ca = a.run, &cb = b.run;
  if (ca.has_fingerprint && cb.has_fingerprint) {
    if (ca.machine_id != cb.machine_id)
      rep.warnings.push_back(fmt::format("different machine: machine_id {} -> {} ({})", clip_text(ca.machine_id),
                                         clip_text(cb.machine_id),
                                         joined(differences(ca.identity, cb.identity))));
    if (ca.gpu_id != cb.gpu_id) rep.warnings.push_back(fmt::format("different GPU: {} -> {}", clip_text(ca.gpu_name), clip_text(cb.gpu_name)));
    const auto build = differences(ca.build, cb.build);
    std::vector<std::string> real;  // the revision differing is the point of comparing
    for (const auto& d : build)
      if (d.rfind("build.git_revision", 0) != 0 && d.rfind("build.source_commit", 0) != 0) real.push_back(d);
    if (!real.empty()) rep.warnings.push_back("different build: " + joined(real));
    return;
  }
  for (const BenchFile* f : {&a, &b})
    if (!f->run.has_fingerprint)
      rep.notes.push_back(fmt::format("{} has no machine fingerprint (written before pathbench had one): the machine "
                                      "is judged by Google Benchmark's CPU facts only",
                                      f->path));
  const auto cpu = differences(ca.gb_machine, cb.gb_machine);
  if (!cpu.empty()) rep.warnings.push_back("different machine: " + joined(cpu));
  const auto build = differences(ca.gb_build, cb.gb_build);
  if (!build.empty()) rep.warnings.push_back("different build: " + joined(build));
}

void check_settings(const BenchFile& a, const BenchFile& b, CompareReport& rep) {
  std::vector<std::string> d = differences(a.run.settings, b.run.settings);
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
  const double la = a.run.load1, lb = b.run.load1;
  const double cpus = std::max(1.0, b.run.num_cpus >= 0 ? b.run.num_cpus : a.run.num_cpus);
  if (la >= 0 && lb >= 0) {
    if (std::fabs(la - lb) > std::max(0.5, 0.25 * cpus))
      rep.warnings.push_back(fmt::format("different load: 1-minute load average at the start {:.2f} -> {:.2f} on {} "
                                         "CPUs (another process was running)",
                                         la, lb, cpus));
    else if (std::max(la, lb) > 0.5 * cpus)
      rep.notes.push_back(fmt::format("both runs started on a busy machine (load {:.2f} and {:.2f} on {} CPUs)", la,
                                      lb, cpus));
  }
  const double ca = a.run.cpu_per_wall, cb = b.run.cpu_per_wall;
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
