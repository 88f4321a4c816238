// `pathbench compare`: the Mann-Whitney U test against SciPy's values, verdicts on the
// committed fixtures (tests/data/bench/), exit statuses of the command line.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <cstdio>

#include "pathbench/analysis/bench_compare.h"
#include "pathbench/common/errors.h"

namespace {

using pb::analysis::CompareOptions;
using pb::analysis::mann_whitney_u;
using pb::analysis::run_compare;

const std::string kData = std::string(PATHBENCH_SOURCE_DIR) + "/tests/data/bench/";

int compare(const std::string& base, const std::string& next, double threshold = 0.05, double alpha = 0.05) {
  CompareOptions o;
  o.base = base;
  o.next = next;
  o.threshold = threshold;
  o.alpha = alpha;
  return run_compare(o);
}

// A copy of `in` with every iteration's time (and rays/s inversely) scaled by `f`.
std::string scaled_copy(const std::string& in, double f, const std::string& name) {
  nlohmann::json j = pb::analysis::read_benchmark_json(in);
  for (auto& b : j["benchmarks"]) {
    for (const char* k : {"real_time", "cpu_time"})
      if (b.contains(k)) b[k] = b[k].get<double>() * f;
    if (b.contains("rays_per_second")) b["rays_per_second"] = b["rays_per_second"].get<double>() / f;
  }
  const std::string out = std::string(PATHBENCH_TEST_TMP) + "/" + name;
  std::ofstream(out) << j.dump(1);
  return out;
}

// A copy of `in` with the wall time of every iteration scaled by `f` and its CPU time
// left as it was: what another process taking the cores does.
std::string wall_only_copy(const std::string& in, double f, const std::string& name) {
  nlohmann::json j = pb::analysis::read_benchmark_json(in);
  for (auto& b : j["benchmarks"])
    if (b.contains("real_time")) b["real_time"] = b["real_time"].get<double>() * f;
  const std::string out = std::string(PATHBENCH_TEST_TMP) + "/" + name;
  std::ofstream(out) << j.dump(1);
  return out;
}

// Runs the command line; returns its exit status and (in *out) its stdout.
// The output file is this process's own: CTest runs each test as a process of its own,
// several at once (-j), and a shared name let one test read another's output.
int cli_out(const std::string& args, std::string* out) {
  static int calls = 0;
  const std::string file =
      std::string(PATHBENCH_TEST_TMP) + "/cli-out-" + std::to_string(getpid()) + "-" + std::to_string(calls++) + ".txt";
  const std::string cmd = std::string(PATHBENCH_CLI) + " compare " + args + " > " + file + " 2>/dev/null";
  const int st = std::system(cmd.c_str());
  std::ifstream in(file);
  out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  in.close();
  std::remove(file.c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

int cli(const std::string& args) {
  const std::string cmd = std::string(PATHBENCH_CLI) + " compare " + args + " > /dev/null 2>&1";
  const int st = std::system(cmd.c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

TEST(MannWhitney, ExactMatchesScipy) {
  // scipy.stats.mannwhitneyu(a, b, alternative='two-sided', method='exact')
  std::vector<double> a{1, 2, 3, 4, 5, 6, 7, 8, 9}, b{10, 11, 12, 13, 14, 15, 16, 17, 18};
  auto r = mann_whitney_u(a, b);
  EXPECT_TRUE(r.exact);
  EXPECT_DOUBLE_EQ(r.u_a, 0.0);
  EXPECT_NEAR(r.p, 4.113533525298231e-05, 1e-12);

  std::vector<double> c{2.5, 3.5, 4.5, 5.5, 6.5, 7.5, 8.5, 9.5, 10.5};
  std::vector<double> d{1, 2, 3, 4, 5, 6, 7, 8, 9};
  r = mann_whitney_u(c, d);
  EXPECT_DOUBLE_EQ(r.u_a, 53.0);
  EXPECT_NEAR(r.p, 0.29732620320855613, 1e-12);
}

TEST(MannWhitney, TiesUseNormalApproximationLikeScipy) {
  // scipy: method='asymptotic', use_continuity=True -> U = 13, p = 0.015934147250231023
  std::vector<double> a{1, 2, 2, 3, 3, 3, 4, 5, 6}, b{3, 4, 4, 5, 5, 6, 7, 7, 8};
  auto r = mann_whitney_u(a, b);
  EXPECT_FALSE(r.exact);
  EXPECT_DOUBLE_EQ(r.u_a, 13.0);
  EXPECT_NEAR(r.p, 0.015934147250231023, 1e-12);
}

TEST(MannWhitney, AllEqualGivesPOne) {
  std::vector<double> a(9, 1.0);
  EXPECT_DOUBLE_EQ(mann_whitney_u(a, a).p, 1.0);
}

TEST(Compare, IdenticalIsNotARegression) {
  EXPECT_EQ(compare(kData + "base.json", kData + "identical.json"), 0);
  EXPECT_EQ(compare(kData + "base.json", kData + "base.json"), 0);
}

TEST(Compare, TenPercentSlowerIsARegression) {
  EXPECT_EQ(compare(kData + "base.json", kData + "slower10.json"), 1);
  // The other way round it is an improvement, not a regression.
  EXPECT_EQ(compare(kData + "slower10.json", kData + "base.json"), 0);
  // A 10% slowdown below a 15% threshold is not one either.
  EXPECT_EQ(compare(kData + "base.json", kData + "slower10.json", 0.15), 0);
}

TEST(Compare, NoisyButEqualIsNotARegression) {
  EXPECT_EQ(compare(kData + "noisy-a.json", kData + "noisy-b.json"), 0);
  EXPECT_EQ(compare(kData + "noisy-b.json", kData + "noisy-a.json"), 0);
}

TEST(Compare, VerdictsPerBenchmark) {
  auto base = pb::analysis::load_benchmark_json(kData + "base.json", 9);
  auto slow = pb::analysis::load_benchmark_json(kData + "slower10.json", 9);
  auto rows = pb::analysis::compare_files(base, slow, 0.05, 0.05);
  ASSERT_EQ(rows.size(), 3u);
  for (const auto& r : rows) {
    EXPECT_EQ(r.verdict, pb::analysis::Verdict::Regressed) << r.name;
    EXPECT_NEAR(r.time_change, 0.10, 1e-9) << r.name;
    EXPECT_TRUE(r.has_rays);
    EXPECT_NEAR(r.rays_change, 1 / 1.1 - 1, 1e-9) << r.name;
  }
}

TEST(Compare, BadInputIsAnInputError) {
  EXPECT_THROW(compare(kData + "does-not-exist.json", kData + "base.json"), pb::InputError);
  EXPECT_THROW(compare(kData + "base.json", kData + "not-benchmark.json"), pb::InputError);
  EXPECT_THROW(compare(kData + "base.json", kData + "too-few-repetitions.json"), pb::InputError);
  EXPECT_THROW(compare(kData + "aggregates-only.json", kData + "base.json"), pb::InputError);
  EXPECT_THROW(compare(kData + "make_fixtures.py", kData + "base.json"), pb::InputError);
  try {
    compare(kData + "base.json", kData + "too-few-repetitions.json");
  } catch (const pb::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("at least 9"), std::string::npos) << e.what();
  }
}

// The acceptance check on a real 9-repetition quick run of this machine.
TEST(Compare, RealQuickRun) {
  const std::string real = kData + "quick-9rep.json";
  EXPECT_EQ(compare(real, real), 0);
  EXPECT_EQ(compare(real, scaled_copy(real, 1.1, "quick-9rep-x1.1.json")), 1);
}

TEST(CompareCli, ExitStatuses) {
  EXPECT_EQ(cli(kData + "base.json " + kData + "identical.json"), 0);
  EXPECT_EQ(cli(kData + "base.json " + kData + "slower10.json"), 1);
  EXPECT_EQ(cli(kData + "noisy-a.json " + kData + "noisy-b.json --threshold 0.05 --alpha 0.05"), 0);
  EXPECT_EQ(cli(kData + "base.json " + kData + "missing.json"), 2);
  EXPECT_EQ(cli(kData + "base.json " + kData + "not-benchmark.json"), 2);
  EXPECT_EQ(cli(kData + "base.json " + kData + "too-few-repetitions.json"), 2);
  EXPECT_EQ(cli(kData + "base.json"), 2);  // NEW missing
}

TEST(CompareContext, NoCommonNameIsRefused) {
  EXPECT_THROW(compare(kData + "base.json", kData + "other-names.json"), pb::InputError);
  EXPECT_EQ(cli(kData + "base.json " + kData + "other-names.json"), 2);
}

TEST(CompareContext, ZeroTimesAreNotAnImprovement) {
  auto rows = pb::analysis::compare_files(pb::analysis::load_benchmark_json(kData + "base.json", 9),
                                     pb::analysis::load_benchmark_json(kData + "zero-times.json", 9), 0.05, 0.05);
  for (const auto& r : rows) EXPECT_EQ(r.verdict, pb::analysis::Verdict::Invalid) << r.name;
  EXPECT_EQ(cli(kData + "base.json " + kData + "zero-times.json"), 2);  // nothing left to compare
  EXPECT_EQ(cli(kData + "zero-times.json " + kData + "base.json"), 2);
}

TEST(CompareContext, OtherMachineWarnsAndStrictRefuses) {
  std::string out;
  EXPECT_EQ(cli_out(kData + "base.json " + kData + "other-machine.json", &out), 0);
  EXPECT_NE(out.find("WARNING: different machine"), std::string::npos) << out;
  EXPECT_NE(out.find("mhz_per_cpu: 2445 -> 2596"), std::string::npos) << out;
  EXPECT_EQ(cli(kData + "base.json " + kData + "other-machine.json --strict"), 2);
  EXPECT_EQ(cli(kData + "base.json " + kData + "identical.json --strict"), 0);
}

TEST(CompareContext, OtherLayoutWarnsAndStrictRefuses) {
  std::string out;
  EXPECT_EQ(cli_out(kData + "base.json " + kData + "layout-triangles.json --format json", &out), 0);
  const auto j = nlohmann::json::parse(out);
  ASSERT_EQ(j["warnings"].size(), 1u) << out;
  EXPECT_NE(j["warnings"][0].get<std::string>().find("different Embree layout in 3 benchmark(s)"), std::string::npos);
  EXPECT_EQ(cli(kData + "base.json " + kData + "layout-triangles.json --strict"), 2);
}

// Two real runs of the same binary (tests/data/bench/README.md): the second with eight
// busy loops beside it. Wall time went up 12-17 fold, CPU time by a sixth to a third:
// contended, not a regression; --strict refuses the pair.
TEST(CompareContext, RealContendedRunIsFlaggedContended) {
  auto rows = pb::analysis::compare_files(pb::analysis::load_benchmark_json(kData + "quick-quiet.json", 9),
                                     pb::analysis::load_benchmark_json(kData + "quick-contended.json", 9), 0.05, 0.05);
  ASSERT_FALSE(rows.empty());
  for (const auto& r : rows) {
    EXPECT_EQ(r.verdict, pb::analysis::Verdict::Contended) << r.name;
    EXPECT_TRUE(r.has_cpu && r.diverges) << r.name;
  }
  std::string out;
  EXPECT_EQ(cli_out(kData + "quick-quiet.json " + kData + "quick-contended.json", &out), 0);
  EXPECT_NE(out.find("contended"), std::string::npos) << out;
  EXPECT_EQ(cli(kData + "quick-quiet.json " + kData + "quick-contended.json --strict"), 2);
}

TEST(CompareContext, WallUpCpuFlatIsContendedBothUpIsRegression) {
  const std::string real = kData + "quick-9rep.json";
  auto base = pb::analysis::load_benchmark_json(real, 9);
  auto wall = pb::analysis::load_benchmark_json(wall_only_copy(real, 1.3, "quick-wall-1.3.json"), 9);
  auto both = pb::analysis::load_benchmark_json(scaled_copy(real, 1.3, "quick-both-1.3.json"), 9);
  // (One real series, occluded1/coherent, is too spread for p < 0.05 at +30%: "same".)
  const auto by_wall = pb::analysis::compare_files(base, wall, 0.05, 0.05);
  const auto by_both = pb::analysis::compare_files(base, both, 0.05, 0.05);
  for (const auto& r : by_wall) EXPECT_NE(r.verdict, pb::analysis::Verdict::Regressed) << r.name;
  for (const auto& r : by_both) EXPECT_NE(r.verdict, pb::analysis::Verdict::Contended) << r.name;
  EXPECT_GE(pb::analysis::count_verdict(by_wall, pb::analysis::Verdict::Contended), int(by_wall.size()) - 1);
  EXPECT_GE(pb::analysis::count_verdict(by_both, pb::analysis::Verdict::Regressed), int(by_both.size()) - 1);
}

TEST(CompareCli, Formats) {
  std::string out;
  EXPECT_EQ(cli_out(kData + "base.json " + kData + "slower10.json --format json", &out), 1);
  const auto j = nlohmann::json::parse(out);
  EXPECT_EQ(j["verdict"], "regression");
  EXPECT_EQ(j["regressed"], 3);
  EXPECT_NEAR(j["benchmarks"][0]["time_change"].get<double>(), 0.10, 1e-9);
  EXPECT_NEAR(j["benchmarks"][0]["cpu_change"].get<double>(), 0.10, 1e-9);
  EXPECT_EQ(cli_out(kData + "base.json " + kData + "slower10.json --format markdown", &out), 1);
  EXPECT_NE(out.find("| benchmark | base median |"), std::string::npos) << out;
  EXPECT_NE(out.find("**REGRESSED**"), std::string::npos) << out;
  EXPECT_EQ(cli(kData + "base.json " + kData + "slower10.json --format yaml"), 2);
}

}  // namespace
