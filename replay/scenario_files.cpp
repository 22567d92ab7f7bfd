#include "replay/scenario_files.h"

#include "replay/input_file.h"
#include "sim/scenario/json_bounds.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <new>

namespace sg {

Scenario loadScenarioFile(const std::string& path, std::vector<sgr::EmbeddedFile>* files) {
  if (path.empty()) return parseScenario(defaultScenarioText(), "<built-in thesis-meadow>", {});
  std::vector<uint8_t> bytes;
  std::string error;
  if (!readInputFile(path, InputLimits::kScenarioBytes, &bytes, &error)) throw ScenarioError(path, "$", error);
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  auto readRelative = [dir, files](const std::string& name, std::vector<uint8_t>* out, std::string* why) {
    const std::filesystem::path p =
        std::filesystem::path(name).is_absolute() ? std::filesystem::path(name) : dir / name;
    std::string expected;
    if (!readInputFile(p.string(), InputLimits::kHeightmapBytes, out, &expected)) {
      *why = "'" + echoText(name) + "' to be " + expected;  // a scenario's text: bounded
      return false;
    }
    if (files) files->push_back(sgr::EmbeddedFile{name, *out});
    return true;
  };
  return parseScenario(std::string(bytes.begin(), bytes.end()), path, readRelative);
}

std::vector<std::string> filesNamedBy(const Scenario& scenario, const std::vector<sgr::EmbeddedFile>& files,
                                      const std::string& folder) {
  std::vector<std::string> out;
  auto add = [&](const std::string& name) {
    if (name.empty()) return;
    const std::filesystem::path p(name);
    out.push_back(p.is_absolute() ? name : (std::filesystem::path(folder) / p).string());
  };
  for (const sgr::EmbeddedFile& f : files) add(f.name);
  for (const BodySpec& b : scenario.bodies.list) add(b.mesh);
  return out;
}

uint64_t physicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
  uint64_t bytes = pages > 0 && size > 0 ? uint64_t(pages) * uint64_t(size) : 0;
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY && (bytes == 0 || limit.rlim_cur < bytes))
    bytes = uint64_t(limit.rlim_cur);
  return bytes;
}

std::unique_ptr<SimWorld> makeWorldWithinMemory(const Scenario& scenario, int threads) {
  try {
    return makeWorld(scenario, threads, physicalMemoryBytes());
  } catch (const std::bad_alloc&) {
    throw ScenarioError(scenario.sourceName.empty() ? "<built-in>" : scenario.sourceName, "$.field",
                        "a field that fits in memory (allocation failed)");
  }
}
}  // namespace sg
