// Output shared by `simgrass diff` and `simgrass compare`: loading a recording for a command,
// the per-tick CSV columns, numbers in text tables and the JSON of a divergence summary.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "replay/cli/cli_common.h"
#include "replay/divergence.h"
#include "replay/format/sgr_reader.h"
#include "replay/output_file.h"

namespace sg {

/// Reads a recording for `command` ("diff"): a damaged file is one line on stderr and nullptr;
/// a truncated one a warning line (its complete part is used).
std::unique_ptr<sgr::Recording> loadRecordingFor(const char* command, const std::string& path);

/// True when `path` is empty or names a file that can be created (its folder exists and is
/// writable); else one line on stderr: checked before a long run, not after it.
bool canWrite(const char* command, const std::string& path, const char* what);

/// The per-tick CSV header (after `prefix`, e.g. "variant,") and one row (after its prefix).
inline constexpr const char* kTickCsvColumns =
    "tick,tip_max_m,tip_rms_m,body_pos_max_m,body_angle_max_rad,contacts_a,contacts_b,identical";
void writeTickCsvRow(std::FILE* f, const TickDivergence& d);

/// A number for CSV and JSON-like text: enough digits to plot, "nan"/"inf" spelled out.
std::string csvNumber(double v);
/// A CSV field, quoted when it holds a comma, a quote or a newline.
std::string csvField(const std::string& s);
/// A length or angle for a text table: "0" or 3 significant digits in exponent form.
std::string shortNumber(double v);

/// The median of `v` (the mean of the two middle values for an even count; 0 when empty).
double medianOf(std::vector<double> v);

/// The run-level numbers of a summary (metres, radians) as JSON keys.
void summaryJson(const DivergenceSummary& s, nlohmann::json& out);
/// One tick as JSON.
nlohmann::json tickJson(const TickDivergence& d);

/// Writes `header` and then calls rows(FILE*) into memory, then the whole text to `path` with
/// writeFileAtomic (complete or absent, every write checked); false with a one-line stderr
/// message on failure.
template <class Rows>
bool writeCsv(const char* command, const std::string& path, const std::string& header, Rows&& rows) {
  char* data = nullptr;
  size_t size = 0;
  std::FILE* f = open_memstream(&data, &size);
  if (!f) {
    printError("simgrass %s: %s: cannot build the CSV text (out of memory)", command, path.c_str());
    return false;
  }
  std::fprintf(f, "%s\n", header.c_str());
  rows(f);
  const bool built = std::ferror(f) == 0;
  std::fclose(f);  // sets data and size
  const std::string text = data ? std::string(data, size) : std::string();
  std::free(data);
  std::string error;
  if (!built) {
    printError("simgrass %s: %s: cannot build the CSV text", command, path.c_str());
    return false;
  }
  if (!writeFileAtomic(path, text, &error)) {
    printError("simgrass %s: %s", command, error.c_str());
    return false;
  }
  return true;
}

}  // namespace sg
