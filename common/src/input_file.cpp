#include "pathbench/common/input_file.h"

#include <fcntl.h>
#include <fmt/core.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "pathbench/common/errors.h"

namespace pb {

namespace {

// Closes the descriptor on every path out, including exceptions.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

std::string why_not_opened(int err) {
  switch (err) {
    case ENOENT: return "no such file";
    case ENOTDIR: return "no such file (a parent of it is not a directory)";
    case EACCES: return "permission denied";
    case ELOOP: return "too many levels of symbolic links";
    case ENAMETOOLONG: return "the file name is too long";
    default: return std::strerror(err);
  }
}

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// The path for messages: a 1 MB name is cut, not repeated.
std::string shown(const std::string& path) {
  return path.size() <= 200 ? path : path.substr(0, 100) + "..." + path.substr(path.size() - 60);
}

}  // namespace

std::string format_bytes(uint64_t b) {
  if (b >= (uint64_t(1) << 30) && b % (uint64_t(1) << 30) == 0) return fmt::format("{} GiB", b >> 30);
  if (b >= (uint64_t(1) << 20) && b % (uint64_t(1) << 20) == 0) return fmt::format("{} MiB", b >> 20);
  if (b >= (uint64_t(1) << 20)) return fmt::format("{:.1f} MiB", double(b) / double(uint64_t(1) << 20));
  return fmt::format("{} bytes", b);
}

std::string read_input_file(const std::string& path, const char* what, uint64_t max_bytes) {
  if (path.empty()) throw InputError(fmt::format("empty file name for a {}", what));
  if (path.find('\0') != std::string::npos) throw InputError(fmt::format("{}: a file name with a NUL byte", what));
  Fd f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY)};
  if (f.fd < 0) throw InputError(fmt::format("{}: {}", shown(path), why_not_opened(errno)));
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) throw InputError(fmt::format("{}: {}", shown(path), std::strerror(errno)));
  if (!S_ISREG(st.st_mode))
    throw InputError(fmt::format("{}: is {}; a {} must be a regular file", shown(path), kind_of(st.st_mode), what));
  const auto too_big = [&](uint64_t size) {
    return InputError(fmt::format("{}: {}s are limited to {} (this one has {}{})", shown(path), what,
                                  format_bytes(max_bytes), size > max_bytes ? "" : "more than ", format_bytes(size)));
  };
  if (uint64_t(st.st_size) > max_bytes) throw too_big(uint64_t(st.st_size));
  // The file may grow between fstat and read: read at most one byte past the limit.
  std::string text(size_t(st.st_size), '\0');
  size_t used = 0;
  for (;;) {
    if (used == text.size()) {
      if (used > max_bytes) throw too_big(used);
      text.resize(std::min<uint64_t>(max_bytes + 1, std::max<uint64_t>(2 * used, 4096)));
    }
    const ssize_t n = ::read(f.fd, text.data() + used, text.size() - used);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw InputError(fmt::format("{}: read failed: {}", shown(path), std::strerror(errno)));
    }
    if (n == 0) break;
    used += size_t(n);
  }
  if (used > max_bytes) throw too_big(used);
  text.resize(used);
  return text;
}

}  // namespace pb
