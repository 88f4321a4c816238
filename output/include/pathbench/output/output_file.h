#pragma once
// Every file pathbench writes (images, reports, tables, benchmark JSON) goes through
// OutputFile: a unique temporary name in the target folder (".NAME.XXXXXX.tmp",
// created exclusively, so two writers to one path never share it), every write and
// the close checked, fsync, then an atomic rename. A reader of the final path sees
// either the old file or one writer's complete new file, never a mix or a prefix.
// Any failure (full disk, read-only folder, a directory in the way) is an InputError
// naming the path: exit status 2, and the temporary file is removed.
#include <sys/types.h>

#include <cstddef>
#include <string>
#include <vector>

namespace pb {

// `path` for messages: names over 160 bytes are shortened to their start and end, so
// that a 1 MB --out does not become a 1 MB error message.
std::string display_path(const std::string& path);

// Checks before any work that `path` can be written as an output file: not a
// directory, not under a regular file, no name component over the file system's
// limit, no symlink loop, and a file can be created in its folder (or the nearest
// existing ancestor, which then must be a writable directory). Throws InputError
// starting with `option` (e.g. "--out") when given. Leaves nothing behind.
void check_output_path(const std::string& path, const std::string& option = "");

class OutputFile {
 public:
  // Creates the parent folders and the temporary file. Throws InputError.
  explicit OutputFile(std::string path);
  OutputFile(OutputFile&& other) noexcept;
  OutputFile& operator=(OutputFile&&) = delete;
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  // Removes the temporary file unless commit() succeeded.
  ~OutputFile();

  const std::string& path() const { return path_; }
  const std::string& temp_path() const { return temp_; }
  int fd() const { return fd_; }

  // Writes all n bytes at the current end or throws InputError (e.g. ENOSPC, EFBIG).
  void write(const void* data, size_t n);
  void write(const std::string& text) { write(text.data(), text.size()); }
  // Writes all n bytes at `offset`; false with errno set on failure (for callers
  // that must not throw, such as an OpenImageIO proxy).
  bool write_at(const void* data, size_t n, off_t offset) noexcept;
  // fsync + close, both checked: afterwards the temporary file is complete on disk.
  void finish();
  // finish() if not yet done, then renames the temporary file over path().
  void commit();
  // Throws the InputError for a failed write of this file, with errno's reason.
  [[noreturn]] void fail(const std::string& what, int err) const;

 private:
  std::string path_, temp_;
  int fd_ = -1;
  int slot_ = -1;        // this temp file's entry in the signal-cleanup table
  bool finished_ = false, committed_ = false;
};

// Commits a set of outputs of one run (an image, its variance, its report): a fatal
// signal meanwhile (install_output_signal_cleanup) waits until all are renamed into
// place, so it leaves all of them or, if it came first, none.
void commit_all(std::vector<OutputFile>& files);

// Writes `text` to `path` through an OutputFile.
void write_text_file(const std::string& path, const std::string& text);

// SIGINT, SIGTERM, SIGHUP and SIGQUIT: remove every temporary file still open, print
// one line to stderr, and die by the same signal (the shell's status is 128 + the
// signal number). A signal the parent set to be ignored stays ignored. For programs
// (the `pathbench` command line), not for libraries loaded into someone else's
// process (the Python module).
void install_output_signal_cleanup();
// A child process to pass such a signal on to (`pathbench bench` runs
// pathbench-bench as a child); 0 for none.
void forward_signals_to(pid_t child);

// For a command that must remove finished files of its own on such a signal (crosscheck:
// its images and exported scene): while one lives, the signal does not end the process
// at once. It is recorded (signal()) and passed on to the child set_child() names, unless
// the terminal sent it to the whole process group; a second signal kills that child. The
// owner looks at signal() at its safe points, removes what it wrote and calls stop(),
// which ends the process by that signal (the shell's status: 128 + its number). A
// signal still recorded when it is destroyed ends the process then. One at a time.
class DeferredSignals {
 public:
  DeferredSignals();
  ~DeferredSignals();
  DeferredSignals(const DeferredSignals&) = delete;
  DeferredSignals& operator=(const DeferredSignals&) = delete;
  int signal() const;  // the signal recorded, 0 for none
  static void set_child(pid_t child);  // 0 for none
  [[noreturn]] void stop() const;
};

}  // namespace pb
