#include "replay/scenario_files.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace sg {
namespace {
bool readBytes(const std::filesystem::path& path, std::vector<uint8_t>* out, std::string* error) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    *error = "an existing file, '" + path.string() + "' was not found";
    return false;
  }
  if (std::filesystem::is_directory(path, ec)) {
    *error = "a file, '" + path.string() + "' is a directory";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *error = "a readable file, '" + path.string() + "': " + std::strerror(errno);
    return false;
  }
  out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return true;
}
}  // namespace

Scenario loadScenarioFile(const std::string& path, std::vector<sgr::EmbeddedFile>* files) {
  if (path.empty()) return parseScenario(defaultScenarioText(), "<built-in thesis-meadow>", {});
  std::vector<uint8_t> bytes;
  std::string error;
  if (!readBytes(path, &bytes, &error)) throw ScenarioError(path, "$", error);
  if (bytes.size() > (size_t(64) << 20)) throw ScenarioError(path, "$", "a scenario file under 64 MiB");
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  auto readRelative = [dir, files](const std::string& name, std::vector<uint8_t>* out, std::string* why) {
    const std::filesystem::path p =
        std::filesystem::path(name).is_absolute() ? std::filesystem::path(name) : dir / name;
    if (!readBytes(p, out, why)) return false;
    if (files) files->push_back(sgr::EmbeddedFile{name, *out});
    return true;
  };
  return parseScenario(std::string(bytes.begin(), bytes.end()), path, readRelative);
}

uint64_t physicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && size > 0 ? uint64_t(pages) * uint64_t(size) : 0;
}
}  // namespace sg
