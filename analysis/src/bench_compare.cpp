#include "pathbench/analysis/bench_compare.h"

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <mutex>
#include <numeric>
#include <optional>

#include "compare_context.h"
#include "json_fields.h"
#include "pathbench/common/display_text.h"
#include "pathbench/common/errors.h"
#include "pathbench/common/input_file.h"
#include "pathbench/common/json_input.h"
#include "pathbench/common/limits.h"

namespace pb::analysis {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

namespace {

// Number of arrangements of m a's and n b's with U_a == u, for every u (no ties):
// c(m, n, u) = c(m - 1, n, u - n) + c(m, n - 1, u).
std::vector<double> exact_u_counts(size_t m, size_t n) {
  // dp[i][j] is a vector over u of size i*j+1; build row by row.
  std::vector<std::vector<std::vector<double>>> dp(m + 1, std::vector<std::vector<double>>(n + 1));
  for (size_t i = 0; i <= m; ++i)
    for (size_t j = 0; j <= n; ++j) {
      std::vector<double>& c = dp[i][j];
      c.assign(i * j + 1, 0.0);
      if (i == 0 || j == 0) {
        c[0] = 1;
        continue;
      }
      // Largest element is an a (beats all j b's) or a b.
      const auto& pa = dp[i - 1][j];
      for (size_t u = 0; u < pa.size(); ++u) c[u + j] += pa[u];
      const auto& pb = dp[i][j - 1];
      for (size_t u = 0; u < pb.size(); ++u) c[u] += pb[u];
    }
  return dp[m][n];
}

}  // namespace

MannWhitneyResult mann_whitney_u(const std::vector<double>& a, const std::vector<double>& b) {
  MannWhitneyResult r;
  const size_t m = a.size(), n = b.size();
  if (m == 0 || n == 0) return r;
  // Midranks over the pooled sample.
  std::vector<std::pair<double, int>> pooled;
  pooled.reserve(m + n);
  for (double x : a) pooled.push_back({x, 0});
  for (double x : b) pooled.push_back({x, 1});
  std::sort(pooled.begin(), pooled.end(), [](auto& l, auto& r) { return l.first < r.first; });
  const size_t N = m + n;
  double rank_sum_a = 0, tie_term = 0;
  bool ties = false;
  for (size_t i = 0; i < N;) {
    size_t j = i;
    while (j < N && pooled[j].first == pooled[i].first) ++j;
    const double t = double(j - i);
    const double mid = 0.5 * double(i + 1 + j);  // ranks i+1 .. j
    for (size_t k = i; k < j; ++k)
      if (pooled[k].second == 0) rank_sum_a += mid;
    if (t > 1) {
      ties = true;
      tie_term += t * t * t - t;
    }
    i = j;
  }
  r.u_a = rank_sum_a - double(m) * double(m + 1) / 2.0;
  const double mn = double(m) * double(n);
  const double u_min = std::min(r.u_a, mn - r.u_a);

  if (!ties && m <= 50 && n <= 50) {
    // Cached per (m, n): the table costs O(m^2 n^2) and a file may hold thousands of
    // benchmarks with the same repetition counts.
    static std::mutex cache_mutex;
    static std::map<std::pair<size_t, size_t>, std::vector<double>> cache;
    std::unique_lock lock(cache_mutex);
    auto [it, fresh] = cache.try_emplace({m, n});
    if (fresh) it->second = exact_u_counts(m, n);
    const std::vector<double> counts = it->second;
    lock.unlock();
    const double total = std::accumulate(counts.begin(), counts.end(), 0.0);
    double tail = 0;
    for (size_t u = 0; u < counts.size() && double(u) <= u_min + 1e-9; ++u) tail += counts[u];
    r.p = std::min(1.0, 2.0 * tail / total);
    r.exact = true;
    return r;
  }
  const double mu = mn / 2.0;
  const double var = mn / 12.0 * ((double(N) + 1.0) - tie_term / (double(N) * double(N - 1)));
  if (var <= 0) {
    r.p = 1;  // every value equal
    return r;
  }
  const double z = std::max(0.0, std::fabs(r.u_a - mu) - 0.5) / std::sqrt(var);
  r.p = std::min(1.0, std::erfc(z / std::sqrt(2.0)));
  return r;
}

namespace {

constexpr size_t kMaxBenchmarkName = 1024;

double unit_to_seconds(const std::string& unit, const std::string& path, const std::string& name) {
  if (unit == "ns") return 1e-9;
  if (unit == "us") return 1e-6;
  if (unit == "ms") return 1e-3;
  if (unit == "s") return 1.0;
  throw InputError(fmt::format("{}: benchmark '{}' has unknown time_unit '{}'", path, name, unit));
}

}  // namespace

namespace {

bool word_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// Google Benchmark writes NaN for undefined aggregates (e.g. the cv of a constant
// counter); strict JSON has no NaN, so a value NaN, nan, Infinity or inf (after a ':',
// optionally negative) is read as null. A linear scan: std::regex recurses per
// character and overflows the stack on long runs of whitespace.
std::string non_finite_to_null(const std::string& raw) {
  static const char* const kWords[] = {"NaN", "nan", "Infinity", "inf"};
  std::string out;
  out.reserve(raw.size());
  size_t i = 0;
  while (i < raw.size()) {
    out += raw[i];
    if (raw[i++] != ':') continue;
    size_t j = i;
    while (j < raw.size() && std::isspace(static_cast<unsigned char>(raw[j]))) ++j;
    const size_t value = j;
    if (j < raw.size() && raw[j] == '-') ++j;
    for (const char* w : kWords) {
      const size_t n = std::strlen(w);
      if (raw.compare(j, n, w) == 0 && (j + n == raw.size() || !word_char(raw[j + n]))) {
        out.append(raw, i, value - i);
        out += "null";
        i = j + n;
        break;
      }
    }
  }
  return out;
}

}  // namespace

namespace {

// Benchmark JSON text with NaN/Infinity read as null, as `Json` (ordered or not).
template <class Json> Json parse_benchmark_as(const std::string& path, const std::string& raw) {
  try {
    return parse_json_bounded<Json>(non_finite_to_null(raw), path);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: not JSON ({})", path, e.what()));
  }
}

}  // namespace

// The same text as ordered JSON (key order kept), for rewriting a bench file in place.
nlohmann::ordered_json parse_benchmark_json_text(const std::string& raw, const std::string& path) {
  return parse_benchmark_as<nlohmann::ordered_json>(path, raw);
}

nlohmann::json parse_benchmark_json(const std::string& path, const std::string& raw) {
  return parse_benchmark_as<nlohmann::json>(path, raw);
}

nlohmann::json read_benchmark_json(const std::string& path) {
  return parse_benchmark_json(path, read_input_file(path, "benchmark JSON file", limits::kMaxBenchJsonBytes));
}

BenchFile load_benchmark_json(const std::string& path, int min_repetitions) {
  return bench_file_from_json(path, read_benchmark_json(path), min_repetitions);
}

BenchFile bench_file_from_json(const std::string& path, const nlohmann::json& j, int min_repetitions) try {
  const auto list = j.is_object() ? j.find("benchmarks") : j.end();
  if (!j.is_object() || list == j.end() || !list->is_array() || !j.contains("context"))
    throw InputError(fmt::format("{}: not Google Benchmark JSON (expected an object with 'context' and a "
                                 "'benchmarks' array; write it with --benchmark_out=FILE.json)",
                                 path));
  BenchFile f;
  f.path = path;
  f.context = j.at("context");
  f.run = read_bench_context(path, f.context);
  if (!f.context.is_object()) f.context = nlohmann::json::object();
  std::map<std::string, bool> has_aggregates;
  for (size_t i = 0; i < list->size(); ++i) {
    const nlohmann::json& b = (*list)[i];
    const std::string where = fmt::format("benchmarks[{}]", i);
    if (!b.is_object()) fields::wrong(path, where, "an object", b);
    const fields::Reader r(path, b, where);
    const std::optional<std::string> run_name = r.string("run_name"), plain_name = r.string("name");
    if (!plain_name) throw InputError(fmt::format("{}: {}: missing (every benchmark has a name)", path, r.field("name")));
    const std::string name = run_name.value_or(*plain_name);
    // The table pads every row to the longest name: a megabyte name times thousands of
    // rows would be gigabytes of output.
    if (name.size() > kMaxBenchmarkName)
      throw InputError(fmt::format("{}: {}: a benchmark name of {} bytes (at most {})", path,
                                   r.field(run_name ? "run_name" : "name"), name.size(), kMaxBenchmarkName));
    const std::string run_type = r.string_or("run_type", "iteration");
    if (!f.series.count(name)) f.order.push_back(name);
    BenchSeries& s = f.series[name];
    if (r.boolean("error_occurred").value_or(false)) {
      s.error = true;
      s.error_message = r.string_or("error_message", "error");
      continue;
    }
    if (run_type == "aggregate") {
      has_aggregates[name] = true;
      continue;
    }
    // Times and counters: any finite number (a negative or zero time is judged "invalid"
    // by compare_files, not refused here); null is Google Benchmark's NaN: not given.
    constexpr double kBig = std::numeric_limits<double>::max();
    const std::optional<double> real_time = r.number("real_time", -kBig, kBig);
    if (!real_time)
      throw InputError(fmt::format("{}: {}: missing (benchmark '{}' has no numeric 'real_time')", path,
                                   r.field("real_time"), name));
    if (!r.number("iterations", 0, kBig))
      throw InputError(fmt::format("{}: {}: missing (benchmark '{}')", path, r.field("iterations"), name));
    const std::string unit = r.string_or("time_unit", "ns");
    const double scale = unit_to_seconds(unit, path, name);
    s.seconds.push_back(*real_time * scale);
    if (const auto rays = r.number("rays_per_second", -kBig, kBig)) s.rays_per_second.push_back(*rays);
    // Both read (and so type-checked) whichever is used.
    const auto process = r.number("process_cpu_seconds", -kBig, kBig), cpu = r.number("cpu_time", -kBig, kBig);
    if (process) {
      s.cpu_seconds.push_back(*process);
      s.cpu_is_process = true;
    } else if (cpu) {
      s.cpu_seconds.push_back(*cpu * scale);
    }
    if (const auto throttled = r.number("throttled", -kBig, kBig); throttled && *throttled > 0) s.throttled = true;
    if (const auto label = r.string("label"); label && !label->empty()) s.labels.insert(*label);
    // A counter named like Google Benchmark's own "threads" key was a duplicate key in
    // older files; parsing keeps the last, which was the counter.
    for (const char* k : {"cpu_threads", "threads"})
      if (const auto t = r.number(k, -kBig, kBig); t && s.cpu_threads < 0) s.cpu_threads = *t;
  }
  if (f.series.empty()) throw InputError(fmt::format("{}: the file lists no benchmarks", path));
  for (const auto& name : f.order) {
    const BenchSeries& s = f.series[name];
    if (s.error) continue;
    if (int(s.seconds.size()) < min_repetitions) {
      std::string why = s.seconds.empty() && has_aggregates[name]
                            ? "only aggregates (run with --benchmark_report_aggregates_only=false)"
                            : fmt::format("{} repetition(s)", s.seconds.size());
      throw InputError(fmt::format("{}: benchmark '{}' has {}; the U test needs at least {} "
                                   "(run with --benchmark_repetitions={} --benchmark_report_aggregates_only=false)",
                                   path, name, why, min_repetitions, min_repetitions));
    }
  }
  return f;
} catch (const nlohmann::json::exception& e) {
  // A field of the wrong type ("name": 5, "run_type": []): bad input, not a failure.
  throw InputError(fmt::format("{}: not Google Benchmark JSON ({})", path, e.what()));
}

const char* to_string(Verdict v) {
  switch (v) {
    case Verdict::Same: return "same";
    case Verdict::Regressed: return "REGRESSED";
    case Verdict::Improved: return "improved";
    case Verdict::Contended: return "contended";
    case Verdict::Invalid: return "invalid";
    case Verdict::Error: return "error";
    case Verdict::OnlyBase: return "only in base";
    case Verdict::OnlyNew: return "only in new";
  }
  return "?";
}

std::vector<CompareRow> compare_files(const BenchFile& base, const BenchFile& next, double threshold, double alpha) {
  std::vector<CompareRow> rows;
  std::vector<std::string> names = base.order;
  for (const auto& n : next.order)
    if (!base.series.count(n)) names.push_back(n);
  for (const auto& name : names) {
    CompareRow row;
    row.name = name;
    auto bi = base.series.find(name);
    auto ni = next.series.find(name);
    if (ni == next.series.end()) {
      row.verdict = Verdict::OnlyBase;
    } else if (bi == base.series.end()) {
      row.verdict = Verdict::OnlyNew;
    } else if (bi->second.error || ni->second.error) {
      row.verdict = Verdict::Error;
      row.note = bi->second.error ? bi->second.error_message : ni->second.error_message;
    } else {
      const BenchSeries &b = bi->second, &n = ni->second;
      row.base_median_s = median(b.seconds);
      row.new_median_s = median(n.seconds);
      if (!(row.base_median_s > 0) || !(row.new_median_s > 0)) {
        // A zero time is no measurement: "improved -100%" would be a lie.
        row.verdict = Verdict::Invalid;
        row.note = fmt::format("median time is zero in {}", row.base_median_s > 0 ? "new" : "base");
        rows.push_back(row);
        continue;
      }
      row.time_change = row.new_median_s / row.base_median_s - 1;
      if (!b.rays_per_second.empty() && !n.rays_per_second.empty()) {
        const double rb = median(b.rays_per_second), rn = median(n.rays_per_second);
        row.has_rays = rb > 0;
        row.rays_change = rb > 0 ? rn / rb - 1 : 0;
      }
      if (!b.cpu_seconds.empty() && !n.cpu_seconds.empty() && b.cpu_is_process == n.cpu_is_process) {
        row.base_cpu_s = median(b.cpu_seconds);
        row.new_cpu_s = median(n.cpu_seconds);
        row.has_cpu = row.base_cpu_s > 0 && row.new_cpu_s > 0;
        if (row.has_cpu) {
          row.cpu_change = row.new_cpu_s / row.base_cpu_s - 1;
          row.diverges = std::fabs(row.time_change - row.cpu_change) > std::max(threshold, 0.05);
        }
      }
      row.test = mann_whitney_u(n.seconds, b.seconds);
      const bool significant = row.test.p < alpha;
      if (significant && row.time_change > threshold) {
        // Slower in wall time: contended when the work (CPU time of every thread) did
        // not grow with it, i.e. the process waited for cores it did not get.
        // "Flat" is relative: sharing cores and caches with another process costs some
        // CPU time too (+17% and +35% in tests/data/bench/quick-contended.json), so the test is
        // that less than half of the slowdown is more work.
        const bool cpu_flat = row.has_cpu && row.cpu_change < row.time_change / 2;
        row.verdict = cpu_flat ? Verdict::Contended : Verdict::Regressed;
        if (cpu_flat)
          row.note = fmt::format("wall {:+.1f}%, CPU {:+.1f}%: waited for cores", 100 * row.time_change,
                                 100 * row.cpu_change);
      } else if (significant && row.time_change < -threshold) {
        row.verdict = Verdict::Improved;
      } else {
        row.verdict = Verdict::Same;
      }
      if (row.diverges && row.note.empty())
        row.note = fmt::format("wall {:+.1f}% but CPU {:+.1f}%", 100 * row.time_change, 100 * row.cpu_change);
      // A run whose GPU lowered its clocks (power or thermal, NVML's clock-event reasons)
      // measured the cooling, not the code: say so beside any verdict.
      if (b.throttled || n.throttled) {
        const std::string t = fmt::format("THROTTLED in {}", b.throttled && n.throttled ? "both" : b.throttled ? "base" : "new");
        row.note = row.note.empty() ? t : row.note + "; " + t;
      }
    }
    rows.push_back(row);
  }
  return rows;
}

int count_verdict(const std::vector<CompareRow>& rows, Verdict v) {
  return int(std::count_if(rows.begin(), rows.end(), [v](const CompareRow& r) { return r.verdict == v; }));
}

int run_compare(const CompareOptions& o) {
  if (!(o.threshold >= 0)) throw InputError("--threshold: must be >= 0");
  if (!(o.alpha > 0 && o.alpha < 1)) throw InputError("--alpha: must be in (0, 1)");
  if (o.min_repetitions < 2) throw InputError("--min-repetitions: must be at least 2");
  if (o.format != "text" && o.format != "json" && o.format != "markdown")
    throw InputError(fmt::format("--format: unknown format '{}' (expected text, json or markdown)", o.format));
  const BenchFile base = load_benchmark_json(o.base, o.min_repetitions);
  const BenchFile next = load_benchmark_json(o.next, o.min_repetitions);
  CompareReport rep;
  rep.base_path = o.base;
  rep.new_path = o.next;
  rep.threshold = o.threshold;
  rep.alpha = o.alpha;
  rep.rows = compare_files(base, next, o.threshold, o.alpha);
  const int matched = int(rep.rows.size()) - count_verdict(rep.rows, Verdict::OnlyBase) -
                      count_verdict(rep.rows, Verdict::OnlyNew);
  if (matched == 0)
    throw InputError(fmt::format("{} and {} have no benchmark name in common: nothing to compare", o.base, o.next));
  if (count_verdict(rep.rows, Verdict::Invalid) + count_verdict(rep.rows, Verdict::Error) == matched)
    throw InputError(fmt::format("{} / {}: no benchmark in common has a usable time (zero times or errors)",
                                 o.base, o.next));
  describe_runs(base, next, rep);
  if (o.strict && !rep.warnings.empty()) {
    for (const auto& w : rep.warnings) fmt::print(stderr, "warning: {}\n", terminal_safe(w));
    throw InputError(fmt::format("--strict: the runs differ ({} warning(s) above); not comparing",
                                 rep.warnings.size()));
  }
  const bool any = count_verdict(rep.rows, Verdict::Regressed) > 0;
  if (o.format == "json") {
    // ASCII with \u escapes: a name's C1 controls or bidirectional overrides are not
    // written raw to a terminal either. Strings from the files are UTF-8 (the parser
    // checks); a path from the command line may not be: U+FFFD then, not a failure.
    fmt::print("{}\n", format_json(rep).dump(2, ' ', true, nlohmann::json::error_handler_t::replace));
  } else if (o.format == "markdown") {
    fmt::print("{}", format_markdown(rep));
  } else {
    if (!o.quiet) fmt::print("{}", format_text(rep));
    fmt::print("{}\n", any ? "pathbench compare: REGRESSION" : "pathbench compare: no regression");
  }
  return any ? 1 : 0;
}

}  // namespace pb::analysis
