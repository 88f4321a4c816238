#pragma once
// The table of temporary output files that a fatal signal must remove (internal to
// output_file.cpp; the public switch is pb::install_output_signal_cleanup).
#include <signal.h>

namespace pb::detail {

// Records a temporary file's path; returns its slot, or -1 when the table is full
// or the path too long (the file is then still removed on every normal exit path).
int register_temp_file(const char* path) noexcept;
void unregister_temp_file(int slot) noexcept;

// A stretch of code that creates, renames or (un)registers output files. Blocking
// the signals on this thread is not enough: a process-directed signal is then
// handled by another thread (TBB's workers), which could remove files while this one
// has created a file it has not yet registered, or has renamed only some of a set
// of outputs. So the handler also waits, on any thread, until no such section is
// open, and a section that opens after a signal arrived never starts its work (the
// thread waits for the process to end).
class FileChangeSection {
 public:
  FileChangeSection() noexcept;
  ~FileChangeSection();
  FileChangeSection(const FileChangeSection&) = delete;
  FileChangeSection& operator=(const FileChangeSection&) = delete;

 private:
  sigset_t old_;
};

}  // namespace pb::detail
