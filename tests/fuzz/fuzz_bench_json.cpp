// compare's benchmark JSON reader on arbitrary bytes; what it accepts is then compared
// with itself and with a copy whose times are 10% slower, and formatted as a table.
#include "pathbench/analysis/bench_compare.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = pb::fuzz::text_of(data, size);
  pb::fuzz::expect_clean([&] {
    const nlohmann::json j = pb::analysis::parse_benchmark_json("fuzz/bench.json", text);
    const pb::analysis::BenchFile base = pb::analysis::bench_file_from_json("fuzz/bench.json", j, 2);
    pb::analysis::BenchFile slower = base;
    for (auto& [name, series] : slower.series)
      for (double& s : series.seconds) s *= 1.1;
    for (const pb::analysis::BenchFile* next : {&base, static_cast<const pb::analysis::BenchFile*>(&slower)}) {
      const auto rows = pb::analysis::compare_files(base, *next, 0.05, 0.05);
      (void)pb::analysis::format_table(rows, 0.05, 0.05);
    }
  });
  return 0;
}
