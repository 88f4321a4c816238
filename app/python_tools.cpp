#include "python_tools.h"

#include <fmt/core.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "pathbench/common/errors.h"
#include "pathbench/output/output_file.h"

#ifndef PATHBENCH_SOURCE_DIR
#define PATHBENCH_SOURCE_DIR ""
#endif

namespace pb::app {

namespace fs = std::filesystem;

namespace {

fs::path executable_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v && *v ? std::string(v) : std::string();
}

bool is_tools_dir(const fs::path& p) {
  std::error_code ec;
  return !p.empty() && fs::is_regular_file(p / "history" / "__main__.py", ec);
}

// Checks the modules, then runs the target as __main__ with argv[0] its own name.
constexpr const char* kBootstrap = R"(import importlib.util, runpy, sys
cmd, need, target = sys.argv[1], sys.argv[2], sys.argv[3]
missing = [m for m in need.split(",") if m and importlib.util.find_spec(m) is None]
if missing:
    quiet = cmd.startswith("?")
    sys.stderr.write(("%s: note:" if quiet else "pathbench: error: %s:") % cmd.lstrip("?") + " the Python at %s lacks %s (pip install %s into it, or set PATHBENCH_PYTHON to a Python that has it)\n" % (sys.executable, ", ".join(missing), " ".join(missing)))
    sys.exit(2)
if not target:
    sys.exit(0)
sys.argv = [target] + sys.argv[4:]
if target.endswith(".py"):
    runpy.run_path(target, run_name="__main__")
else:
    runpy.run_module(target, run_name="__main__", alter_sys=True)
)";

}  // namespace

std::string find_python_tools(std::string* looked) {
  std::vector<fs::path> places;
  if (std::string e = env("PATHBENCH_TOOLS_DIR"); !e.empty()) places.emplace_back(e);
  if (fs::path dir = executable_dir(); !dir.empty()) places.push_back(dir.parent_path() / "share" / "pathbench" / "tools");
  if (*PATHBENCH_SOURCE_DIR) places.push_back(fs::path(PATHBENCH_SOURCE_DIR) / "tools");
  for (const fs::path& p : places)
    if (is_tools_dir(p)) return p.string();
  if (looked) {
    looked->clear();
    for (const fs::path& p : places) *looked += (looked->empty() ? "" : ", ") + p.string();
  }
  return {};
}

std::string find_python() {
  if (std::string e = env("PATHBENCH_PYTHON"); !e.empty()) return e;
  std::error_code ec;
  if (fs::path dir = executable_dir(); !dir.empty() && fs::exists(dir / "python3", ec)) return (dir / "python3").string();
  if (*PATHBENCH_SOURCE_DIR) {
    const fs::path venv = fs::path(PATHBENCH_SOURCE_DIR) / ".venv" / "bin" / "python";
    if (fs::exists(venv, ec)) return venv.string();
  }
  return "python3";
}

int run_python_tool(const PythonTool& tool, const std::vector<std::string>& args, bool quiet_if_missing) {
  std::string looked;
  const std::string tools = find_python_tools(&looked);
  if (tools.empty()) {
    if (!quiet_if_missing)
      fmt::print(stderr,
                 "pathbench: error: {}: cannot find pathbench's Python tools (looked in {}); install pathbench with "
                 "`cmake --install` or `pip install .`, or set PATHBENCH_TOOLS_DIR\n",
                 tool.command, looked);
    return kPythonToolMissing;
  }
  const std::string python = find_python();
  std::string need;
  for (const std::string& m : tool.modules) need += (need.empty() ? "" : ",") + m;
  const std::string target = tool.target.ends_with(".py") ? (fs::path(tools) / tool.target).string() : tool.target;
  std::vector<std::string> all{python, "-c", kBootstrap, (quiet_if_missing ? "?" : "") + tool.command, need, target};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::string path = tools;
  if (std::string old = env("PYTHONPATH"); !old.empty()) path += ":" + old;
  std::fflush(stdout);
  std::fflush(stderr);
  int pipefd[2];  // the child reports a failed exec through it (close-on-exec: silent on success)
  if (pipe2(pipefd, O_CLOEXEC) != 0) throw std::runtime_error(fmt::format("{}: pipe: {}", tool.command, std::strerror(errno)));
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(fmt::format("{}: fork: {}", tool.command, std::strerror(errno)));
  if (pid == 0) {
    close(pipefd[0]);
    setenv("PYTHONPATH", path.c_str(), 1);
    execvp(argv[0], argv.data());
    const int err = errno;
    (void)!write(pipefd[1], &err, sizeof err);
    _exit(kExitBadInput);
  }
  close(pipefd[1]);
  int exec_errno = 0;
  ssize_t n;
  while ((n = read(pipefd[0], &exec_errno, sizeof exec_errno)) < 0 && errno == EINTR) {
  }
  close(pipefd[0]);
  int status = 0;
  DeferredSignals::set_child(pid);  // a command that defers signals (crosscheck) passes them on
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  DeferredSignals::set_child(0);
  if (n == sizeof exec_errno) {
    if (!quiet_if_missing)
      fmt::print(stderr, "pathbench: error: {}: cannot run Python '{}': {} (set PATHBENCH_PYTHON to a Python 3)\n",
                 tool.command, python, std::strerror(exec_errno));
    return kPythonToolMissing;
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return kExitFailed;
}

}  // namespace pb::app
