// compare's context and its three outputs on arbitrary bytes. The input is one or two
// JSON texts separated by a line "%%": each is a whole benchmark file when it is an
// object with "benchmarks", else the "context" of a fixed file of two benchmarks (two
// repetitions each, names from the fuzzer's own strings too). Both files are read
// (bench_file_from_json: every context field typed), compared, described
// (describe_runs: machine, build, settings, load) and written as text, Markdown and
// JSON. Besides what expect_clean counts (anything but an InputError escaping, a crash,
// a sanitizer report), these are findings: a raw control character in the text output,
// a Markdown table line whose cells do not number 8, JSON output that does not parse.
#include <nlohmann/json.hpp>

#include <string>

#include "compare_context.h"
#include "fuzz_util.h"
#include "pathbench/analysis/bench_compare.h"

namespace {

using Json = nlohmann::json;

// A file around `context`: two benchmarks, one named by a string of the context where it has one.
Json file_around(const Json& context) {
  std::string name = "bm/fuzz";
  if (context.is_object())
    if (auto it = context.find("name"); it != context.end() && it->is_string()) name = it->get<std::string>();
  Json benchmarks = Json::array();
  for (const std::string& n : {std::string("bm/plain"), name})
    for (double t : {1.0, 1.5})
      benchmarks.push_back({{"name", n}, {"run_name", n}, {"run_type", "iteration"}, {"iterations", 10},
                            {"real_time", t}, {"cpu_time", t}, {"time_unit", "ms"}, {"label", "embree_layout=quads"}});
  return {{"context", context}, {"benchmarks", benchmarks}};
}

bool raw_control(const std::string& s) {
  for (size_t i = 0; i < s.size(); ++i) {
    const auto b = static_cast<unsigned char>(s[i]);
    if ((b < 0x20 && b != '\n') || b == 0x7F) return true;
    if (b == 0xC2 && i + 1 < s.size() && static_cast<unsigned char>(s[i + 1]) >= 0x80 &&
        static_cast<unsigned char>(s[i + 1]) <= 0x9F)
      return true;  // a C1 control (U+0080..U+009F)
  }
  return false;
}

// Every line of the Markdown table has 9 '|' that no backslash escapes (8 cells).
bool table_intact(const std::string& md) {
  size_t start = 0;
  while (start < md.size()) {
    size_t end = md.find('\n', start);
    if (end == std::string::npos) end = md.size();
    if (md[start] == '|') {
      int pipes = 0;
      for (size_t i = start; i < end; ++i)
        if (md[i] == '|' && (i == start || md[i - 1] != '\\')) ++pipes;
      if (pipes != 9) return false;
    }
    start = end + 1;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = pb::fuzz::text_of(data, size);
  const size_t cut = text.find("\n%%\n");
  const std::string parts[2] = {text.substr(0, cut), cut == std::string::npos ? "{}" : text.substr(cut + 4)};
  pb::fuzz::expect_clean([&] {
    pb::analysis::BenchFile files[2];
    for (int k = 0; k < 2; ++k) {
      const std::string path = k ? "fuzz/new.json" : "fuzz/base\x1b[31m.json";
      const Json j = pb::analysis::parse_benchmark_json(path, parts[k]);
      const bool whole = j.is_object() && j.contains("benchmarks");
      files[k] = pb::analysis::bench_file_from_json(path, whole ? j : file_around(j), 2);
    }
    pb::analysis::CompareReport rep;
    rep.base_path = files[0].path;
    rep.new_path = files[1].path;
    rep.rows = pb::analysis::compare_files(files[0], files[1], 0.05, 0.05);
    pb::analysis::describe_runs(files[0], files[1], rep);
    if (raw_control(pb::analysis::format_text(rep))) __builtin_trap();
    if (!table_intact(pb::analysis::format_markdown(rep))) __builtin_trap();
    const std::string json = pb::analysis::format_json(rep).dump(2, ' ', false, Json::error_handler_t::replace);
    if (!Json::accept(json)) __builtin_trap();
  });
  return 0;
}
