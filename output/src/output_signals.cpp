// Removing temporary output files when a fatal signal arrives. The handler may run
// at any instruction of any thread, so it only reads a fixed table of paths (no
// allocation, no locks) and calls async-signal-safe functions: unlink, kill, write,
// sigaction, raise.
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>

#include "output_signals.h"
#include "pathbench/output/output_file.h"

namespace pb {
namespace detail {
namespace {

constexpr int kSlots = 32;
constexpr size_t kMaxPath = 4096;

// A slot's path is written before `used` is set (release) and read only after
// `used` is seen set (acquire), so the handler never reads a half-written path.
struct Slot {
  std::atomic<bool> used{false};
  std::atomic<bool> claimed{false};
  char path[kMaxPath];
};
std::array<Slot, kSlots> g_slots;
std::atomic<pid_t> g_child{0};
// Dekker-style gate between FileChangeSection and the handler (both sequentially
// consistent): either the section sees g_stopping set, or the handler sees g_open > 0.
std::atomic<int> g_open{0};
std::atomic<bool> g_stopping{false};
// Sections open on this thread: one opened inside another (commit_all's commits)
// must finish, since the handler is already waiting for the outer one.
thread_local int t_depth = 0;

constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

// Waits (async-signal-safely) until no FileChangeSection is open: they are short (a
// create, a rename, an fsync), but a stuck disk must not keep a signal from ending
// the process, so the wait gives up after 10 s.
void wait_for_open_sections() {
  const timespec step{0, 1'000'000};  // 1 ms
  for (int i = 0; i < 10'000 && g_open.load() > 0; ++i) ::nanosleep(&step, nullptr);
}

const char* signal_name(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    case SIGQUIT: return "SIGQUIT";
  }
  return "a signal";
}

bool remove_temp_files() {
  bool removed = false;
  for (Slot& s : g_slots)
    if (s.used.load(std::memory_order_acquire)) removed |= ::unlink(s.path) == 0;
  return removed;
}

void say_stopped(int sig, const char* tail) {
  const char* name = signal_name(sig);
  ssize_t ignored = ::write(STDERR_FILENO, "\npathbench: ", 12);
  ignored = ::write(STDERR_FILENO, name, std::strlen(name));
  ignored = ::write(STDERR_FILENO, tail, std::strlen(tail));
  (void)ignored;
}

void on_fatal_signal(int sig) {
  const int saved = errno;
  g_stopping.store(true);
  wait_for_open_sections();
  const pid_t child = g_child.load(std::memory_order_acquire);
  if (child > 0) ::kill(child, sig);
  say_stopped(sig, remove_temp_files() ? ": stopped; temporary output files removed\n" : ": stopped\n");
  errno = saved;
  // SA_RESETHAND restored the default action; the signal is blocked while this
  // handler runs, so it is delivered (and ends the process) as the handler returns.
  ::raise(sig);
}

// DeferredSignals: the first signal is recorded for the owner to act on and passed to
// the child unless the terminal sent it (then the child's process group has it too:
// a second copy would interrupt the child's own cleanup); a second one kills the
// child, so an unresponsive child cannot keep the owner from stopping.
std::atomic<bool> g_deferred{false};
std::atomic<int> g_pending{0};
std::atomic<pid_t> g_deferred_child{0};

void install_handler(int sig);

void on_signal(int sig, siginfo_t* info, void*) {
  if (!g_deferred.load()) return on_fatal_signal(sig);
  const int saved = errno;
  const pid_t child = g_deferred_child.load(std::memory_order_acquire);
  int expected = 0;
  if (g_pending.compare_exchange_strong(expected, sig)) {
    if (child > 0 && !(info && info->si_code == SI_KERNEL)) ::kill(child, sig);
  } else if (child > 0) {
    ::kill(child, SIGKILL);
  }
  install_handler(sig);  // SA_RESETHAND restored the default action
  errno = saved;
}

void install_handler(int sig) {
  struct sigaction sa {};
  sa.sa_sigaction = on_signal;
  sigemptyset(&sa.sa_mask);
  for (int other : kCleanupSignals) sigaddset(&sa.sa_mask, other);  // one cleanup at a time
  sa.sa_flags = SA_RESETHAND | SA_SIGINFO;
  ::sigaction(sig, &sa, nullptr);
}

}  // namespace

FileChangeSection::FileChangeSection() noexcept {
  sigset_t s;
  sigemptyset(&s);
  for (int sig : kCleanupSignals) sigaddset(&s, sig);
  pthread_sigmask(SIG_BLOCK, &s, &old_);
  g_open.fetch_add(1);
  if (t_depth++ == 0 && g_stopping.load()) {
    // A handler on another thread is removing files and will end the process; this
    // thread must not create or rename one behind it.
    g_open.fetch_sub(1);
    for (;;) ::pause();
  }
}

FileChangeSection::~FileChangeSection() {
  --t_depth;
  g_open.fetch_sub(1);
  pthread_sigmask(SIG_SETMASK, &old_, nullptr);
}

int register_temp_file(const char* path) noexcept {
  const size_t n = std::strlen(path);
  if (n >= kMaxPath) return -1;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (!g_slots[i].claimed.compare_exchange_strong(expected, true, std::memory_order_acq_rel)) continue;
    std::memcpy(g_slots[i].path, path, n + 1);
    g_slots[i].used.store(true, std::memory_order_release);
    return i;
  }
  return -1;
}

void unregister_temp_file(int slot) noexcept {
  if (slot < 0 || slot >= kSlots) return;
  g_slots[slot].used.store(false, std::memory_order_release);
  g_slots[slot].claimed.store(false, std::memory_order_release);
}

}  // namespace detail

void install_output_signal_cleanup() {
  for (int sig : detail::kCleanupSignals) {
    struct sigaction old {};
    if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;  // e.g. nohup, `cmd &`
    detail::install_handler(sig);
  }
}

void forward_signals_to(pid_t child) { detail::g_child.store(child, std::memory_order_release); }

DeferredSignals::DeferredSignals() {
  detail::g_pending.store(0);
  detail::g_deferred.store(true);
}

DeferredSignals::~DeferredSignals() {
  detail::g_deferred.store(false);
  detail::g_deferred_child.store(0);
  // A signal recorded and never acted on still ends the process, as it would have.
  if (const int sig = detail::g_pending.exchange(0)) ::raise(sig);
}

int DeferredSignals::signal() const { return detail::g_pending.load(); }

void DeferredSignals::set_child(pid_t child) { detail::g_deferred_child.store(child, std::memory_order_release); }

void DeferredSignals::stop() const {
  const int sig = detail::g_pending.load();
  detail::g_deferred.store(false);
  detail::remove_temp_files();
  detail::say_stopped(sig, ": stopped; the files this run wrote are removed\n");
  struct sigaction sa {};
  sa.sa_handler = SIG_DFL;
  sigemptyset(&sa.sa_mask);
  ::sigaction(sig, &sa, nullptr);
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, sig);
  pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
  ::raise(sig);
  ::_exit(128 + sig);  // not reached: the default action ends the process
}

}  // namespace pb
