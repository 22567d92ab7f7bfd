#include "replay/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <vector>

namespace sg {

bool writeFileAtomic(const std::string& path, std::span<const uint8_t> bytes, std::string* error) {
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
    *error = path + ": cannot create a file in " + folder.string() + " (" + std::strerror(errno) + ")";
    return false;
  }
  auto fail = [&](const char* what) {
    *error = path + ": " + what + " (" + std::strerror(errno) + ")";
    ::close(fd);
    ::unlink(name.data());
    return false;
  };
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return fail("cannot write");
    done += size_t(n);
  }
  if (::fsync(fd) != 0 && errno != EINVAL) return fail("cannot flush to disk");
  if (::close(fd) != 0) {
    *error = path + ": cannot close (" + std::strerror(errno) + ")";
    ::unlink(name.data());
    return false;
  }
  // The permissions an ordinary open() would have given (mkstemp makes the file 0600).
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::chmod(name.data(), 0666 & ~mask);
  if (std::rename(name.data(), path.c_str()) != 0) {
    *error = path + ": cannot replace the file (" + std::strerror(errno) + ")";
    ::unlink(name.data());
    return false;
  }
  return true;
}

}  // namespace sg
