// Recording a session: steps a world with the given inputs and streams INPT, CHCK, SNAP and END
// chunks to a `.sgr` file (replay/format/). Used by `simgrass record` and the viewer.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "replay/format/sgr_writer.h"
#include "replay/variant.h"
#include "sim/world/world.h"

namespace sg {

struct RecordSettings {
  uint32_t checkEvery = 1;       ///< 0: no CHCK chunks
  uint32_t snapshotEvery = 300;  ///< 0: no SNAP chunks
  int zstdLevel = 3;
};

/// The default CHCK interval for a scene: 1 up to ~100,000 patches, then fewer so that hashing
/// stays under ~3% of a tick (it reads the whole state).
uint32_t defaultCheckEvery(int64_t patches);

/// "simgrass <version> <compiler> <build type>".
std::string buildId();

class Recorder {
 public:
  /// `scenario` has the variant already applied; `files` are the files it named (embedded).
  /// Writes HEAD with the world's current state hash. Throws std::runtime_error on I/O errors.
  Recorder(const std::string& path, const Scenario& scenario, std::vector<sgr::EmbeddedFile> files, SimWorld& world,
           const RecordSettings& settings);
  ~Recorder();  ///< a recorder destroyed without finish() leaves a truncated (still readable) file

  /// One tick: records the input, steps the world, writes CHCK/SNAP when due, flushes.
  StepResult step(const TickInput& input, StageObserver* observer = nullptr);
  /// Writes END (final tick and hash, or the fault) and closes the file.
  void finish(const StepResult& last = {});
  uint64_t bytesWritten() const { return writer_.bytesWritten(); }

 private:
  SimWorld& world_;
  RecordSettings settings_;
  int64_t startTick_;
  int64_t lastNamedTick_;  ///< the last tick a chunk names (the reader bounds the gaps: sgr::kMaxTickGap)
  sgr::Writer writer_;
  bool finished_ = false;
};

}  // namespace sg
