#include "pathbench/output/output_file.h"

#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/core.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string_view>
#include <utility>
#include <vector>

#include "output_signals.h"
#include "pathbench/common/errors.h"

namespace fs = std::filesystem;

namespace pb {

namespace {

// Cuts `s` at byte `i` or earlier so that no UTF-8 sequence is split.
size_t char_boundary(const std::string& s, size_t i) {
  while (i > 0 && i < s.size() && (static_cast<unsigned char>(s[i]) & 0xC0) == 0x80) --i;
  return i;
}

std::string reason(int err) { return std::strerror(err); }

[[noreturn]] void refuse(const std::string& option, const std::string& path, const std::string& why) {
  if (option.empty()) throw InputError(fmt::format("{}: {}", display_path(path), why));
  throw InputError(fmt::format("{} {}: {}", option, display_path(path), why));
}

// Creates ".NAME.XXXXXX.tmp" in `dir` ("" = the current folder) exclusively, with a
// random part, and returns its descriptor (-1 and errno on failure). The name part
// is cut so that the temporary name stays within NAME_MAX.
int create_temp(const std::string& dir, const std::string& name, std::string& temp) {
  const std::string stem = name.substr(0, char_boundary(name, std::min<size_t>(name.size(), NAME_MAX - 16)));
  temp = (dir.empty() ? std::string() : dir + "/") + "." + stem + ".XXXXXX.tmp";
  std::vector<char> buf(temp.begin(), temp.end());
  buf.push_back('\0');
  const int fd = ::mkostemps(buf.data(), 4, O_CLOEXEC);
  temp.assign(buf.data());
  return fd;
}

// The permissions a newly created file gets (0666 less the umask). mkstemp makes its
// files 0600; the finished output should look like any other file the user writes.
// The umask is read from /proc, since umask() can only be read by changing it.
mode_t new_file_mode() {
  static const mode_t mode = [] {
    std::FILE* f = std::fopen("/proc/self/status", "r");
    unsigned mask = 022;
    if (f) {
      char line[256];
      while (std::fgets(line, sizeof line, f))
        if (std::sscanf(line, "Umask: %o", &mask) == 1) break;
      std::fclose(f);
    }
    return mode_t(0666 & ~mask);
  }();
  return mode;
}

// The nearest existing ancestor of `p` (p itself excluded); sets err when a
// component cannot be looked up for another reason than not existing.
fs::path nearest_existing_folder(const fs::path& p, int& err) {
  fs::path dir = p.parent_path();
  err = 0;
  for (;;) {
    if (dir.empty()) return ".";
    struct stat st {};
    if (::stat(dir.c_str(), &st) == 0) return dir;
    if (errno != ENOENT) {
      err = errno;
      return dir;
    }
    if (dir == dir.root_path()) return dir;
    dir = dir.parent_path();
  }
}

}  // namespace

std::string display_path(const std::string& path) {
  constexpr size_t kMax = 160, kHead = 100, kTail = 40;
  if (path.size() <= kMax) return path;
  const size_t head = char_boundary(path, kHead);
  size_t tail = char_boundary(path, path.size() - kTail);
  return fmt::format("{}...[{} bytes]...{}", path.substr(0, head), path.size(), path.substr(tail));
}

void check_output_path(const std::string& path, const std::string& option) {
  if (path.empty()) refuse(option, path, "the file name is empty");
  const fs::path p(path);
  const std::string name = p.filename().string();
  if (name.empty() || name == "." || name == "..") refuse(option, path, "names a directory, not a file");
  for (const auto& part : p) {
    if (part.string().size() > NAME_MAX)
      refuse(option, path,
             fmt::format("a name in it is {} bytes long; file names are at most {} bytes", part.string().size(),
                         NAME_MAX));
  }
  if (path.size() >= PATH_MAX)
    refuse(option, path, fmt::format("the path is {} bytes long; at most {} are allowed", path.size(), PATH_MAX - 1));

  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0) {
    if (S_ISLNK(st.st_mode)) {
      // The rename replaces the link itself; it must not point at a folder, nor loop.
      struct stat target {};
      if (::stat(path.c_str(), &target) == 0) {
        if (S_ISDIR(target.st_mode)) refuse(option, path, "is a directory");
      } else if (errno == ELOOP) {
        refuse(option, path, "is a symbolic link loop");
      }
    } else if (S_ISDIR(st.st_mode)) {
      refuse(option, path, "is a directory");
    } else if (!S_ISREG(st.st_mode)) {
      refuse(option, path, "exists and is not a regular file (a device, FIFO or socket); name a new or regular file");
    }
  } else if (errno != ENOENT) {
    const int err = errno;
    if (err == ELOOP) refuse(option, path, "a symbolic link loop in its folders");
    if (err == ENOTDIR) refuse(option, path, "a folder in the path is a file, not a directory");
    refuse(option, path, reason(err));
  }

  int err = 0;
  const fs::path folder = nearest_existing_folder(p, err);
  if (err) refuse(option, path, fmt::format("{}: {}", display_path(folder.string()), reason(err)));
  struct stat fst {};
  if (::stat(folder.c_str(), &fst) != 0) refuse(option, path, reason(errno));
  if (!S_ISDIR(fst.st_mode)) refuse(option, path, fmt::format("{} is not a directory", display_path(folder.string())));
  // The only test that holds for every reason (permissions, a read-only mount, root,
  // ACLs): create a file there.
  std::string temp;
  detail::FileChangeSection section;  // the probe file is not in the cleanup table
  const int fd = create_temp(folder == "." && !p.has_parent_path() ? "" : folder.string(), name, temp);
  if (fd < 0)
    refuse(option, path, fmt::format("cannot create a file in {}: {}", display_path(folder.string()), reason(errno)));
  ::close(fd);
  ::unlink(temp.c_str());
}

OutputFile::OutputFile(std::string path) : path_(std::move(path)) {
  const fs::path p(path_);
  if (p.filename().empty()) throw InputError(fmt::format("{}: names a directory, not a file", display_path(path_)));
  std::error_code ec;
  if (p.has_parent_path()) {
    fs::create_directories(p.parent_path(), ec);
    if (ec)
      throw InputError(fmt::format("{}: cannot create the folder {}: {}", display_path(path_),
                                   display_path(p.parent_path().string()), ec.message()));
  }
  detail::FileChangeSection section;  // created and registered before a signal can clean up
  fd_ = create_temp(p.has_parent_path() ? p.parent_path().string() : std::string(), p.filename().string(), temp_);
  if (fd_ < 0) {
    const int err = errno;
    temp_.clear();
    throw InputError(fmt::format("{}: cannot create a file in its folder: {}", display_path(path_), reason(err)));
  }
  slot_ = detail::register_temp_file(temp_.c_str());
  ::fchmod(fd_, new_file_mode());  // best effort: the file is usable either way
}

OutputFile::OutputFile(OutputFile&& o) noexcept
    : path_(std::move(o.path_)), temp_(std::move(o.temp_)), fd_(std::exchange(o.fd_, -1)),
      slot_(std::exchange(o.slot_, -1)), finished_(o.finished_), committed_(o.committed_) {
  o.temp_.clear();
}

OutputFile::~OutputFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_ && !temp_.empty()) ::unlink(temp_.c_str());
  detail::unregister_temp_file(slot_);
}

void OutputFile::fail(const std::string& what, int err) const {
  throw InputError(fmt::format("{}: {}: {}", display_path(path_), what, reason(err)));
}

bool OutputFile::write_at(const void* data, size_t n, off_t offset) noexcept {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t w = ::pwrite(fd_, p, n, offset);
    if (w < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    if (w == 0) {  // not an error code, but no progress: treat as a full disk
      errno = ENOSPC;
      return false;
    }
    p += w;
    n -= size_t(w);
    offset += w;
  }
  return true;
}

void OutputFile::write(const void* data, size_t n) {
  if (fd_ < 0 || finished_) throw std::logic_error(fmt::format("{}: write after finish", path_));
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t w = ::write(fd_, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) fail("write failed", w < 0 ? errno : ENOSPC);
    p += w;
    n -= size_t(w);
  }
}

void OutputFile::finish() {
  if (finished_) return;
  if (::fsync(fd_) != 0) fail("write failed (fsync)", errno);
  const int fd = std::exchange(fd_, -1);
  if (::close(fd) != 0) fail("write failed (close)", errno);
  finished_ = true;
}

void OutputFile::commit() {
  finish();
  detail::FileChangeSection section;  // renamed and unregistered before a signal can clean up
  if (::rename(temp_.c_str(), path_.c_str()) != 0) {
    const int err = errno;
    fail(err == EISDIR ? std::string("cannot replace it") : std::string("cannot rename the finished file into place"),
         err);
  }
  committed_ = true;
  // Make the rename itself durable (best effort: some file systems refuse).
  const fs::path folder = fs::path(path_).has_parent_path() ? fs::path(path_).parent_path() : fs::path(".");
  const int dfd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
  detail::unregister_temp_file(slot_);
  slot_ = -1;
}

void commit_all(std::vector<OutputFile>& files) {
  for (OutputFile& f : files) f.finish();
  detail::FileChangeSection section;  // a signal sees all of them renamed, or none
  for (OutputFile& f : files) f.commit();
}

void write_text_file(const std::string& path, const std::string& text) {
  OutputFile f(path);
  f.write(text);
  f.commit();
}

}  // namespace pb
