#include "pathbench/common/progress.h"

#include "pathbench/common/display_text.h"

#include <fmt/core.h>
#include <unistd.h>

#include <cstdio>

namespace pb {

Progress::Progress(std::string label, uint64_t total, bool enabled)
    : label_(terminal_safe(label)),  // the label names the scene: data
      total_(total ? total : 1), enabled_(enabled), tty_(isatty(STDERR_FILENO)) {
  start_ = std::chrono::steady_clock::now();
  if (enabled_) thread_ = std::thread([this] { run(); });
}

Progress::~Progress() { finish(); }

void Progress::finish() {
  {
    std::lock_guard lk(mu_);
    if (stop_) return;
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (enabled_ && shown_) draw(true);
}

void Progress::run() {
  std::unique_lock lk(mu_);
  while (!cv_.wait_for(lk, std::chrono::milliseconds(200), [this] { return stop_; })) {
    auto elapsed = std::chrono::steady_clock::now() - start_;
    if (elapsed < std::chrono::seconds(1)) continue;
    draw(false);
  }
}

void Progress::draw(bool final_line) {
  const uint64_t done = std::min(done_.load(std::memory_order_relaxed), total_);
  const double frac = double(done) / double(total_);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double eta = frac > 0 ? secs / frac - secs : 0;
  if (!tty_) {
    int decile = int(frac * 10);
    if (!final_line && decile == last_decile_) return;
    last_decile_ = decile;
    fmt::print(stderr, "{}: {:3.0f}%  {:.1f} s\n", label_, frac * 100, secs);
    shown_ = true;
    return;
  }
  constexpr int kWidth = 30;
  int fill = int(frac * kWidth);
  std::string bar(size_t(fill), '#');
  bar.resize(kWidth, '.');
  fmt::print(stderr, "\r{} [{}] {:5.1f}%  {:.1f} s, eta {:.1f} s  ", label_, bar, frac * 100, secs,
             final_line ? 0.0 : eta);
  if (final_line) fmt::print(stderr, "\n");
  std::fflush(stderr);
  shown_ = true;
}

}  // namespace pb
