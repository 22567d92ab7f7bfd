#include "replay/output_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <vector>

namespace sg {
namespace {

std::string strerrorOf(int err) { return std::strerror(err); }

/// Writes every byte to `fd`, retrying short writes and EINTR; false with errno set on failure.
/// SIGPIPE is held back while writing (a FIFO whose reader went away must be an EPIPE error line,
/// not the end of the process); a SIGPIPE that arrived meanwhile is taken off the queue.
bool writeAll(int fd, std::span<const uint8_t> bytes) {
  sigset_t pipeOnly;
  sigset_t before;
  sigemptyset(&pipeOnly);
  sigaddset(&pipeOnly, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipeOnly, &before);
  bool ok = true;
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = EIO;
      ok = false;
      break;
    }
    done += size_t(n);
  }
  const int err = errno;
  if (!ok && err == EPIPE && !sigismember(&before, SIGPIPE)) {
    const timespec now{0, 0};
    while (sigtimedwait(&pipeOnly, nullptr, &now) == SIGPIPE) {
    }
  }
  pthread_sigmask(SIG_SETMASK, &before, nullptr);
  errno = err;
  return ok;
}

/// A character device (/dev/null, /dev/full, a terminal) or a FIFO: nothing to rename over, the
/// bytes go straight to it (renaming a temp file there would replace the device or FIFO by a
/// regular file). A FIFO is opened without waiting: no reader is an error, not a hang.
bool writeStraight(const std::string& path, bool fifo, std::span<const uint8_t> bytes, std::string* error) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC | (fifo ? O_NONBLOCK : 0));
  if (fd < 0) {
    if (fifo && errno == ENXIO) {
      *error = path + ": no process reads the FIFO";
    } else {
      *error = path + ": cannot open for writing (" + strerrorOf(errno) + ")";
    }
    return false;
  }
  // Blocking from here on: a reader that is slower than us is waited for, not an EAGAIN error.
  if (fifo) ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  if (!writeAll(fd, bytes)) {
    *error = path + ": cannot write (" + strerrorOf(errno) + ")";
    ::close(fd);
    return false;
  }
  if (::close(fd) != 0) {
    *error = path + ": cannot close (" + strerrorOf(errno) + ")";
    return false;
  }
  return true;
}

/// A regular file or a name not yet taken: temp file in the same folder, checked writes, rename.
bool writeByRename(const std::string& path, std::span<const uint8_t> bytes, std::string* error) {
  const std::filesystem::path target(path);
  const std::filesystem::path folder = target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  // Built by appends: `"." + std::string&&` trips GCC 12's -Wrestrict false positive (PR105329).
  std::string leaf = ".";
  leaf += target.filename().string();
  leaf += ".tmp-XXXXXX";
  const std::string pattern = (folder / leaf).string();
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  const int fd = mkstemp(name.data());
  if (fd < 0) {
    *error = path + ": cannot create a file in " + folder.string() + " (" + strerrorOf(errno) + ")";
    return false;
  }
  auto fail = [&](const char* what) {
    *error = path + ": " + what + " (" + strerrorOf(errno) + ")";
    ::close(fd);
    ::unlink(name.data());
    return false;
  };
  if (!writeAll(fd, bytes)) return fail("cannot write");
  if (::fsync(fd) != 0 && errno != EINVAL) return fail("cannot flush to disk");
  if (::close(fd) != 0) {
    *error = path + ": cannot close (" + strerrorOf(errno) + ")";
    ::unlink(name.data());
    return false;
  }
  // The permissions an ordinary open() would have given (mkstemp makes the file 0600).
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::chmod(name.data(), 0666 & ~mask);
  if (std::rename(name.data(), path.c_str()) != 0) {
    *error = path + ": cannot replace the file (" + strerrorOf(errno) + ")";
    ::unlink(name.data());
    return false;
  }
  return true;
}

/// How many symbolic links are followed before giving up (the kernel's own limit, ELOOP).
constexpr int kMaxLinkHops = 40;

}  // namespace

bool writeFileAtomic(const std::string& path, std::span<const uint8_t> bytes, std::string* error) {
  // What is at the name decides how it is written: renaming over a device, a FIFO or a symbolic
  // link would replace it by a regular file (and /dev/full's full-disk error would never fire).
  std::string resolved = path;
  for (int hop = 0;; ++hop) {
    struct stat st {};
    if (::lstat(resolved.c_str(), &st) != 0) break;  // absent (or unreachable: mkstemp says why)
    if (S_ISREG(st.st_mode)) break;
    if (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode)) return writeStraight(resolved, S_ISFIFO(st.st_mode), bytes, error);
    if (S_ISDIR(st.st_mode)) {
      *error = path + ": expected a file name, got a directory";
      return false;
    }
    if (!S_ISLNK(st.st_mode)) {
      *error = path + ": expected a file name, got " + (S_ISSOCK(st.st_mode) ? "a socket" : "a block device");
      return false;
    }
    // A symbolic link: the link stays, the file it names (existing or not) is written.
    if (hop >= kMaxLinkHops) {
      *error = path + ": cannot resolve the symbolic link (" + strerrorOf(ELOOP) + ")";
      return false;
    }
    std::error_code ec;
    const std::filesystem::path link(resolved);
    const std::filesystem::path to = std::filesystem::read_symlink(link, ec);
    if (ec) {
      *error = path + ": cannot read the symbolic link (" + ec.message() + ")";
      return false;
    }
    resolved = (to.is_absolute() || !link.has_parent_path() ? to : link.parent_path() / to).string();
  }
  if (!writeByRename(resolved, bytes, error)) {
    if (resolved != path) *error = path + " -> " + *error;
    return false;
  }
  return true;
}

}  // namespace sg
