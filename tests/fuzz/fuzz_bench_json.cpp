// compare's benchmark JSON reader on arbitrary bytes; what it accepts is then compared
// with itself and with a copy whose times are 10% slower, and formatted as a table.
#include "compare_command.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = pb::fuzz::text_of(data, size);
  pb::fuzz::expect_clean([&] {
    const nlohmann::json j = pb::app::parse_benchmark_json("fuzz/bench.json", text);
    const pb::app::BenchFile base = pb::app::bench_file_from_json("fuzz/bench.json", j, 2);
    pb::app::BenchFile slower = base;
    for (auto& [name, series] : slower.series)
      for (double& s : series.seconds) s *= 1.1;
    for (const pb::app::BenchFile* next : {&base, static_cast<const pb::app::BenchFile*>(&slower)}) {
      const auto rows = pb::app::compare_files(base, *next, 0.05, 0.05);
      (void)pb::app::format_table(rows, 0.05, 0.05);
    }
  });
  return 0;
}
