// `pathbench compare`'s three outputs: text (a table for terminals), Markdown (for a
// pull request or a notes file) and JSON (for tools). Same content in each.
#include <fmt/core.h>

#include <algorithm>

#include "pathbench/analysis/bench_compare.h"
#include "pathbench/common/display_text.h"

namespace pb::analysis {

namespace {

std::string fmt_time(double s) {
  if (s >= 1) return fmt::format("{:.3f} s", s);
  if (s >= 1e-3) return fmt::format("{:.3f} ms", s * 1e3);
  if (s >= 1e-6) return fmt::format("{:.3f} us", s * 1e6);
  return fmt::format("{:.1f} ns", s * 1e9);
}

bool compared(const CompareRow& r) {
  return r.verdict != Verdict::OnlyBase && r.verdict != Verdict::OnlyNew && r.verdict != Verdict::Error &&
         r.verdict != Verdict::Invalid;
}

std::string pct(bool has, double change) { return has ? fmt::format("{:+.1f}%", 100 * change) : std::string("-"); }

std::string summary(const std::vector<CompareRow>& rows, double threshold, double alpha) {
  return fmt::format(
      "{} benchmark(s): {} regressed, {} improved, {} contended (regressed = two-sided Mann-Whitney U p < {} and "
      "median time more than {:.1f}% slower; contended = so in wall time while CPU time stayed flat)\n",
      rows.size(), count_verdict(rows, Verdict::Regressed), count_verdict(rows, Verdict::Improved),
      count_verdict(rows, Verdict::Contended), alpha, 100 * threshold);
}

// A string of a run summary (compare_context.cpp: run_summary writes each as a string,
// machine_id as a string or null), clipped; `absent` where it is not a string.
std::string run_field(const nlohmann::json& r, const char* key, const char* absent = "unknown") {
  const auto it = r.find(key);
  return it != r.end() && it->is_string() ? clip_text(it->get_ref<const std::string&>(), 200) : std::string(absent);
}

std::string run_line(const char* label, const nlohmann::json& r) {
  return fmt::format("{} {} (git {}, {}, machine {} id {})\n", label, terminal_safe(run_field(r, "path")),
                     terminal_safe(run_field(r, "git_revision")), terminal_safe(run_field(r, "date")),
                     terminal_safe(run_field(r, "machine")), terminal_safe(run_field(r, "machine_id")));
}

// A row's name and note as the text table shows them.
std::string text_name(const CompareRow& r) { return terminal_safe(r.name); }

}  // namespace

std::string format_table(const std::vector<CompareRow>& rows, double threshold, double alpha) {
  size_t w = 9;
  for (const auto& r : rows) w = std::max(w, text_name(r).size());
  std::string out = fmt::format("{:<{}}  {:>12}  {:>12}  {:>8}  {:>8}  {:>8}  {:>9}  {}\n", "benchmark", w,
                                "base median", "new median", "time", "CPU", "rays/s", "p (U)", "verdict");
  out += std::string(w + 2 + 12 + 2 + 12 + 2 + 8 + 2 + 8 + 2 + 8 + 2 + 9 + 2 + 9, '-') + "\n";
  for (const auto& r : rows) {
    const std::string note = r.note.empty() ? "" : " (" + terminal_safe(clip_text(r.note, 400)) + ")";
    if (!compared(r)) {
      out += fmt::format("{:<{}}  {:>12}  {:>12}  {:>8}  {:>8}  {:>8}  {:>9}  {}{}\n", text_name(r), w, "", "", "", "", "",
                         "", to_string(r.verdict), note);
      continue;
    }
    out += fmt::format("{:<{}}  {:>12}  {:>12}  {:>8}  {:>8}  {:>8}  {:>9.2g}  {}{}\n", text_name(r), w,
                       fmt_time(r.base_median_s), fmt_time(r.new_median_s), pct(true, r.time_change),
                       pct(r.has_cpu, r.cpu_change), pct(r.has_rays, r.rays_change), r.test.p, to_string(r.verdict),
                       note);
  }
  out += "\n" + summary(rows, threshold, alpha);
  return out;
}

std::string format_text(const CompareReport& r) {
  std::string out = run_line("base:", r.base_run) + run_line("new: ", r.new_run);
  for (const auto& n : r.notes) out += "note: " + terminal_safe(n) + "\n";
  for (const auto& w : r.warnings) out += "WARNING: " + terminal_safe(w) + "\n";
  return out + "\n" + format_table(r.rows, r.threshold, r.alpha);
}

std::string format_markdown(const CompareReport& r) {
  auto run = [](const nlohmann::json& j) {
    return fmt::format("{} (git {}, {}, machine {})", markdown_code(run_field(j, "path")),
                       markdown_code(run_field(j, "git_revision")), markdown_text(run_field(j, "date")),
                       markdown_code(run_field(j, "machine_id", "").empty() ? run_field(j, "machine")
                                                                              : run_field(j, "machine_id")));
  };
  std::string out = "## pathbench compare\n\n- base: " + run(r.base_run) + "\n- new: " + run(r.new_run) + "\n";
  for (const auto& n : r.notes) out += "- note: " + markdown_text(n) + "\n";
  for (const auto& w : r.warnings) out += "- **warning**: " + markdown_text(w) + "\n";
  out += "\n| benchmark | base median | new median | time | CPU | rays/s | p (U) | verdict |\n";
  out += "|---|---:|---:|---:|---:|---:|---:|---|\n";
  for (const auto& row : r.rows) {
    std::string verdict = to_string(row.verdict);
    if (row.verdict == Verdict::Regressed) verdict = "**" + verdict + "**";
    if (!row.note.empty()) verdict += " (" + markdown_text(clip_text(row.note, 400)) + ")";
    if (!compared(row)) {
      out += fmt::format("| {} | | | | | | | {} |\n", markdown_code(row.name), verdict);
      continue;
    }
    out += fmt::format("| {} | {} | {} | {} | {} | {} | {:.2g} | {} |\n", markdown_code(row.name), fmt_time(row.base_median_s),
                       fmt_time(row.new_median_s), pct(true, row.time_change), pct(row.has_cpu, row.cpu_change),
                       pct(row.has_rays, row.rays_change), row.test.p, verdict);
  }
  return out + "\n" + summary(r.rows, r.threshold, r.alpha);
}

nlohmann::json format_json(const CompareReport& r) {
  using Json = nlohmann::json;
  Json rows = Json::array();
  for (const auto& row : r.rows) {
    const bool c = compared(row);
    Json j = {{"name", row.name}, {"verdict", to_string(row.verdict)}, {"note", row.note}};
    j["base_median_seconds"] = c ? Json(row.base_median_s) : Json(nullptr);
    j["new_median_seconds"] = c ? Json(row.new_median_s) : Json(nullptr);
    j["time_change"] = c ? Json(row.time_change) : Json(nullptr);
    j["base_cpu_seconds"] = c && row.has_cpu ? Json(row.base_cpu_s) : Json(nullptr);
    j["new_cpu_seconds"] = c && row.has_cpu ? Json(row.new_cpu_s) : Json(nullptr);
    j["cpu_change"] = c && row.has_cpu ? Json(row.cpu_change) : Json(nullptr);
    j["wall_cpu_diverge"] = c && row.diverges;
    j["rays_per_second_change"] = c && row.has_rays ? Json(row.rays_change) : Json(nullptr);
    j["p_value"] = c ? Json(row.test.p) : Json(nullptr);
    rows.push_back(j);
  }
  const int regressed = count_verdict(r.rows, Verdict::Regressed);
  return {{"base", r.base_run},
          {"new", r.new_run},
          {"threshold", r.threshold},
          {"alpha", r.alpha},
          {"warnings", r.warnings},
          {"notes", r.notes},
          {"benchmarks", rows},
          {"regressed", regressed},
          {"improved", count_verdict(r.rows, Verdict::Improved)},
          {"contended", count_verdict(r.rows, Verdict::Contended)},
          {"verdict", regressed ? "regression" : "no regression"}};
}

}  // namespace pb::analysis
