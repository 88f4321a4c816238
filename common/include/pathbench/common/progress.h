#pragma once
// A progress bar on stderr for long renders: shown only once a render has run for
// a second, redrawn a few times a second on a terminal, every 10% otherwise.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

namespace pb {

class Progress {
 public:
  Progress(std::string label, uint64_t total, bool enabled);
  ~Progress();
  void advance(uint64_t n) { done_.fetch_add(n, std::memory_order_relaxed); }
  void finish();

 private:
  void run();
  void draw(bool final_line);
  std::string label_;
  uint64_t total_;
  bool enabled_;
  bool tty_;
  std::atomic<uint64_t> done_{0};
  std::chrono::steady_clock::time_point start_;
  std::mutex mu_;
  std::condition_variable cv_;
  bool stop_ = false;
  bool shown_ = false;
  int last_decile_ = -1;
  std::thread thread_;
};

}  // namespace pb
