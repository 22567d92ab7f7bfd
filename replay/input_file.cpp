#include "replay/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

namespace sg {
namespace {
const char* kindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  return "not a regular file";
}
}  // namespace

InputFile::InputFile(InputFile&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), size_(std::exchange(other.size_, 0)) {}

InputFile& InputFile::operator=(InputFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    size_ = std::exchange(other.size_, 0);
  }
  return *this;
}

InputFile::~InputFile() {
  if (fd_ >= 0) ::close(fd_);
}

bool InputFile::open(const std::string& path, uint64_t maxBytes, std::string* expected) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  size_ = 0;
  if (path.empty()) {
    *expected = "a file name (got an empty one)";
    return false;
  }
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer forever. It has no
  // effect on reads from a regular file, the only kind read below.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    const int err = errno;
    *expected = err == ENOENT ? std::string("an existing file (not found)")
                              : std::string("a readable file (") + std::strerror(err) + ")";
    return false;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    *expected = std::string("a readable file (") + std::strerror(errno) + ")";
    ::close(fd);
    return false;
  }
  if (!S_ISREG(st.st_mode)) {
    *expected = std::string("a regular file, got ") + kindOf(st.st_mode);
    ::close(fd);
    return false;
  }
  const uint64_t size = st.st_size < 0 ? 0 : uint64_t(st.st_size);
  if (size > maxBytes) {
    *expected = "a file of at most " + std::to_string(maxBytes) + " bytes, got " + std::to_string(size);
    ::close(fd);
    return false;
  }
  fd_ = fd;
  size_ = size;
  return true;
}

bool InputFile::readAt(uint64_t offset, std::span<uint8_t> out, std::string* expected) const {
  if (fd_ < 0) {
    *expected = "an open file";
    return false;
  }
  size_t done = 0;
  while (done < out.size()) {
    const ssize_t n = ::pread(fd_, out.data() + done, out.size() - done, off_t(offset + done));
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n < 0) {
      *expected = "byte " + std::to_string(offset + done) + " to be readable (" + std::strerror(errno) + ")";
      return false;
    }
    if (n == 0) {
      *expected = std::to_string(out.size() - done) + " more bytes at byte " + std::to_string(offset + done) +
                  " (the file ends early or shrank while being read)";
      return false;
    }
    done += size_t(n);
  }
  return true;
}

bool InputFile::readAll(std::vector<uint8_t>* out, std::string* expected) const {
  out->assign(size_t(size_), 0);
  return readAt(0, *out, expected);
}

bool readInputFile(const std::string& path, uint64_t maxBytes, std::vector<uint8_t>* out, std::string* expected) {
  InputFile f;
  return f.open(path, maxBytes, expected) && f.readAll(out, expected);
}

bool readInputFile(const std::string& path, uint64_t maxBytes, std::string* out, std::string* expected) {
  std::vector<uint8_t> bytes;
  if (!readInputFile(path, maxBytes, &bytes, expected)) return false;
  out->assign(bytes.begin(), bytes.end());
  return true;
}

bool sameFile(const std::string& a, const std::string& b) {
  struct stat sa {
  }, sb{};
  if (::stat(a.c_str(), &sa) != 0 || ::stat(b.c_str(), &sb) != 0) return false;
  return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

}  // namespace sg
