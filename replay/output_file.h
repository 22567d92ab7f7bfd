// Writing an output file so that it is either complete or absent: the bytes go to a temporary
// file in the target's folder, every write and the close are checked, and only then is it renamed
// over the target (rename within a folder is atomic on POSIX file systems). A symbolic link is
// followed (the link stays, the file it names is replaced); a character device (/dev/null,
// /dev/full) or a FIFO is written straight to (a FIFO nobody reads is an error, not a wait); a
// directory, socket or block device is refused.
#pragma once

#include <cstdint>
#include <span>
#include <string>

namespace sg {

/// Writes `bytes` to `path` atomically. On failure returns false, sets *error to one line naming
/// the file and what went wrong, and leaves no temporary file and no partial target behind.
bool writeFileAtomic(const std::string& path, std::span<const uint8_t> bytes, std::string* error);
inline bool writeFileAtomic(const std::string& path, const std::string& text, std::string* error) {
  return writeFileAtomic(path, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(text.data()), text.size()),
                         error);
}

}  // namespace sg
