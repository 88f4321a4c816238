// OutputFile (every output pathbench writes): a unique temporary file beside the
// target, every write checked, an atomic rename; nothing left behind on failure, on
// an exception or on a fatal signal. The command-line side (exit 2, messages,
// concurrent renders, signals during a render) is in tests/cli.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pathbench/common/errors.h"
#include "pathbench/output/image_io.h"
#include "pathbench/output/output_file.h"

namespace fs = std::filesystem;

namespace pb {
namespace {

// A fresh folder per test under the system's temporary folder, named after the
// test process. A "threadsafe" death test re-runs the test in a new process: that one
// inherits the name through the environment and must not wipe the folder.
fs::path fresh_dir(const std::string& name) {
  const char* inherited = std::getenv("PATHBENCH_OUTPUT_TEST_PID");
  const std::string me = std::to_string(::getpid());
  if (!inherited) ::setenv("PATHBENCH_OUTPUT_TEST_PID", me.c_str(), 1);
  const std::string owner = inherited ? inherited : me;
  const fs::path d = fs::temp_directory_path() / ("pathbench-output-file-" + owner + "-" + name);
  if (owner == me) {
    fs::remove_all(d);
    fs::create_directories(d);
  }
  return d;
}

std::vector<std::string> entries(const fs::path& d) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(d)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(OutputFile, WritesThroughATemporaryFileAndRenames) {
  const fs::path d = fresh_dir("rename");
  const std::string path = (d / "out.txt").string();
  OutputFile f(path);
  const std::string temp = fs::path(f.temp_path()).filename().string();
  EXPECT_EQ(temp.rfind(".out.txt.", 0), 0u) << temp;
  EXPECT_EQ(temp.substr(temp.size() - 4), ".tmp") << temp;
  f.write("hello ");
  f.write(std::string("world"));
  EXPECT_FALSE(fs::exists(path)) << "visible before the commit";
  f.commit();
  EXPECT_EQ(slurp(path), "hello world");
  EXPECT_EQ(entries(d), std::vector<std::string>{"out.txt"});
  // Like any file the user writes (mkstemp's 0600 would hide it from others).
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  const mode_t mask = ::umask(022);
  ::umask(mask);
  EXPECT_EQ(st.st_mode & 0777, 0666 & ~mask);
}

TEST(OutputFile, UncommittedFileLeavesNothing) {
  const fs::path d = fresh_dir("uncommitted");
  {
    OutputFile f((d / "a.pfm").string());
    f.write("partial");
    EXPECT_EQ(entries(d).size(), 1u);
  }
  EXPECT_TRUE(entries(d).empty());
  // write_image that throws (a wrong buffer size) leaves nothing either.
  EXPECT_ANY_THROW(write_image((d / "b.pfm").string(), std::vector<float>(5), 2, 2));
  EXPECT_TRUE(entries(d).empty());
}

TEST(OutputFile, TwoWritersOfOnePathNeverMix) {
  const fs::path d = fresh_dir("writers");
  const std::string path = (d / "shared.bin").string();
  const std::string a(1 << 16, 'a'), b(1 << 17, 'b');
  for (int round = 0; round < 50; ++round) {
    std::thread ta([&] { write_text_file(path, a); });
    std::thread tb([&] { write_text_file(path, b); });
    ta.join();
    tb.join();
    const std::string got = slurp(path);
    ASSERT_TRUE(got == a || got == b) << "round " << round << ": " << got.size() << " bytes, a mix";
  }
  EXPECT_EQ(entries(d), std::vector<std::string>{"shared.bin"});
}

TEST(OutputFile, FullDiskIsAnInputErrorAndLeavesNothing) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const fs::path d = fresh_dir("full");
  // A file size limit makes writes fail with EFBIG (SIGXFSZ ignored), as a full disk
  // fails them with ENOSPC; in a child, so the limit does not outlive the test.
  for (const char* name : {"img.pfm", "img.png", "img.exr"}) {
    if (std::string(name) != "img.pfm" && !image_io_has_oiio()) continue;
    const auto write_with_limit = [&] {
      ::signal(SIGXFSZ, SIG_IGN);
      const rlimit limit{4096, 4096};
      ::setrlimit(RLIMIT_FSIZE, &limit);
      std::vector<float> noise(256 * 256 * 3);
      std::mt19937 rng(7);  // noise: no encoder compresses it below the limit
      for (float& v : noise) v = float(rng() % 1000) / 1000.0f;
      try {
        write_image((d / name).string(), noise, 256, 256);
      } catch (const InputError& e) {
        std::fprintf(stderr, "%s\n", e.what());
        std::exit(entries(d).empty() ? 3 : 4);
      }
      std::exit(5);
    };
    EXPECT_EXIT(write_with_limit(), ::testing::ExitedWithCode(3), "write failed: File too large")
        << name;
  }
  EXPECT_TRUE(entries(d).empty());
}

TEST(OutputFile, FatalSignalRemovesTemporaryFiles) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const fs::path d = fresh_dir("signal");
  const auto killed_while_writing = [&] {
    install_output_signal_cleanup();
    OutputFile a((d / "a.exr").string());
    OutputFile b((d / "sub" / "b.json").string());
    a.write("half an image");
    ::raise(SIGTERM);
    std::exit(0);
  };
  EXPECT_EXIT(killed_while_writing(), ::testing::KilledBySignal(SIGTERM),
              "SIGTERM: stopped; temporary output files removed");
  EXPECT_EQ(entries(d), std::vector<std::string>{"sub"});
  EXPECT_TRUE(entries(d / "sub").empty());
}

TEST(OutputFile, CheckOutputPathRefusesUnusablePaths) {
  const fs::path d = fresh_dir("check");
  fs::create_directories(d / "folder.png");
  std::ofstream(d / "plain") << "x";
  const auto message = [](const std::string& path) {
    try {
      check_output_path(path, "--out");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message((d / "folder.png").string()).find("is a directory"), std::string::npos);
  EXPECT_NE(message((d / "plain" / "x.png").string()).find("not a directory"), std::string::npos);
  EXPECT_NE(message((d / std::string(256, 'n')).string()).find("at most 255 bytes"), std::string::npos);
  EXPECT_NE(message("/proc/x.png").find("cannot create a file in /proc"), std::string::npos);
  EXPECT_EQ(message((d / "new" / "deeper" / "x.png").string()), "accepted");
  EXPECT_EQ(message((d / "x.png").string()), "accepted");
  EXPECT_EQ(entries(d), (std::vector<std::string>{"folder.png", "plain"})) << "the check left something";
}

TEST(OutputFile, DisplayPathShortensLongNames) {
  EXPECT_EQ(display_path("short.png"), "short.png");
  const std::string huge = std::string(1 << 20, 'x') + ".png";
  const std::string shown = display_path(huge);
  EXPECT_LT(shown.size(), 200u);
  EXPECT_NE(shown.find("[1048580 bytes]"), std::string::npos) << shown;
  EXPECT_EQ(shown.substr(shown.size() - 4), ".png");
  // Never cuts a UTF-8 sequence: every byte of 'é' (C3 A9) stays paired.
  std::string accents;
  for (int i = 0; i < 200; ++i) accents += "\xC3\xA9";
  const std::string cut = display_path(accents);
  const size_t open = cut.find("...[");
  ASSERT_NE(open, std::string::npos);
  EXPECT_EQ(open % 2, 0u) << "the head ends inside a character";
}

}  // namespace
}  // namespace pb
