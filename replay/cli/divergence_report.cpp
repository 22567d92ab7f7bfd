#include "replay/cli/divergence_report.h"

#include <unistd.h>
#include <cinttypes>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace sg {

std::unique_ptr<sgr::Recording> loadRecordingFor(const char* command, const std::string& path) {
  std::unique_ptr<sgr::Recording> rec;
  try {
    rec = std::make_unique<sgr::Recording>(sgr::readRecording(path));
  } catch (const sgr::RecordingError& e) {
    printError("simgrass %s: %s\n", command, e.what());
    return nullptr;
  }
  if (rec->truncated)
    printError("simgrass %s: warning: %s: byte %" PRIu64 ": expected %s; using the %" PRId64 " ticks before it\n",
               command, path.c_str(), rec->truncatedAt, rec->truncatedExpected.c_str(), rec->lastTick());
  return rec;
}

bool canWrite(const char* command, const std::string& path, const char* what) {
  if (path.empty()) return true;
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path parent = fs::path(path).parent_path();
  const fs::path folder = parent.empty() ? fs::path(".") : parent;
  if (fs::is_directory(folder, ec) && ::access(folder.c_str(), W_OK) == 0 && !fs::is_directory(path, ec)) return true;
  printError("simgrass %s: %s: expected a %s in an existing, writable folder\n", command, path.c_str(), what);
  return false;
}

std::string csvNumber(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string shortNumber(double v) {
  if (v == 0) return "0";
  if (std::isnan(v)) return "nan";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", v);
  return buf;
}

void writeTickCsvRow(std::FILE* f, const TickDivergence& d) {
  std::fprintf(f, "%" PRId64 ",%s,%s,%s,%s,%" PRId64 ",%" PRId64 ",%d\n", d.tick, csvNumber(d.tipMax).c_str(),
               csvNumber(d.tipRms).c_str(), csvNumber(d.bodyPosMax).c_str(), csvNumber(d.bodyAngleMax).c_str(),
               d.contactsA, d.contactsB, d.identical ? 1 : 0);
}

double medianOf(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(mid), v.end());
  const double upper = v[mid];
  if (v.size() % 2 == 1) return upper;
  return (*std::max_element(v.begin(), v.begin() + std::ptrdiff_t(mid)) + upper) / 2.0;
}

void summaryJson(const DivergenceSummary& s, nlohmann::json& out) {
  out["tipMax"] = s.tipMax;
  out["tipMaxTick"] = s.tipMaxTick;
  out["tipRms"] = s.tipRms();
  out["bodyPositionMax"] = s.bodyPosMax;
  out["bodyAngleMax"] = s.bodyAngleMax;
  out["contactDeltaMax"] = s.contactDeltaMax;
}

nlohmann::json tickJson(const TickDivergence& d) {
  return {{"tick", d.tick},
          {"tipMax", d.tipMax},
          {"tipRms", d.tipRms},
          {"bodyPositionMax", d.bodyPosMax},
          {"bodyAngleMax", d.bodyAngleMax},
          {"contactsA", d.contactsA},
          {"contactsB", d.contactsB},
          {"bodiesA", d.bodiesA},  // differ once one run spawned a body the other did not
          {"bodiesB", d.bodiesB},
          {"identical", d.identical}};
}

}  // namespace sg
