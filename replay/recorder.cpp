#include "replay/recorder.h"

#include <xxhash.h>
#include <stdexcept>

namespace sg {

uint32_t defaultCheckEvery(int64_t patches) {
  // Hashing reads the whole state (~48 bytes per particle): every tick up to ~100,000 patches,
  // then spaced so that it stays a few percent of the tick.
  if (patches <= 131072) return 1;
  return uint32_t(std::min<int64_t>(60, (patches + 131071) / 131072));
}

std::string buildId() {
  std::string id = "simgrass";
#ifdef SIMGRASS_VERSION
  id += std::string(" ") + SIMGRASS_VERSION;
#endif
#if defined(__clang__)
  id += " clang " + std::to_string(__clang_major__) + "." + std::to_string(__clang_minor__);
#elif defined(__GNUC__)
  id += " gcc " + std::to_string(__GNUC__) + "." + std::to_string(__GNUC_MINOR__);
#endif
#ifdef NDEBUG
  id += " release";
#else
  id += " debug";
#endif
  return id;
}

namespace {
sgr::Header makeHeader(const Scenario& scenario, std::vector<sgr::EmbeddedFile> files, const SimWorld& world,
                       const RecordSettings& settings) {
  sgr::Header h;
  h.scalar = scenario.scalar;
  h.checkEvery = settings.checkEvery;
  h.snapshotEvery = settings.snapshotEvery;
  h.scenarioText = scenario.text;
  h.scenarioHash = XXH3_64bits(scenario.text.data(), scenario.text.size());
  h.initialStateHash = world.stateHash();
  h.startTick = world.tick();
  h.variant = VariantSettings::resolvedFrom(scenario).describe();
  h.scenarioSource = scenario.sourceName;
  h.files = std::move(files);
  h.buildId = buildId();
  return h;
}
}  // namespace

Recorder::Recorder(const std::string& path, const Scenario& scenario, std::vector<sgr::EmbeddedFile> files,
                   SimWorld& world, const RecordSettings& settings)
    : world_(world),
      settings_(settings),
      startTick_(world.tick()),
      lastNamedTick_(world.tick()),
      writer_(path, makeHeader(scenario, std::move(files), world, settings)) {
  writer_.zstdLevel = settings.zstdLevel;
}

Recorder::~Recorder() = default;

StepResult Recorder::step(const TickInput& input, StageObserver* observer) {
  const int64_t before = world_.tick();
  if (writer_.input(before, input)) lastNamedTick_ = before;
  // On the grid startTick + n * every (the reader insists on it: a missing chunk is damage).
  const int64_t since = before + 1 - startTick_;
  const bool check = settings_.checkEvery > 0 && since % settings_.checkEvery == 0;
  const bool snap = settings_.snapshotEvery > 0 && since % settings_.snapshotEvery == 0;
  // The reader refuses a tick more than kMaxTickGap after the last one the file names: refuse
  // the step instead (the file so far stays a readable, cut-off recording).
  if (!check && !snap && before + 1 - lastNamedTick_ > sgr::kMaxTickGap)
    throw std::runtime_error(
        writer_.path() + ": cannot record more than " + std::to_string(sgr::kMaxTickGap) +
        " ticks without a hash, a snapshot or an input (record with a check or snapshot interval)");
  // The particle pass takes the row groups' digests as it goes, on its threads (state_hash.h).
  if (check || snap) world_.requestStateHash();
  StepResult r = world_.step(input, observer);
  if (r.ok) {
    const int64_t t = world_.tick();
    if (check || snap) lastNamedTick_ = t;
    if (snap) {
      const std::vector<uint8_t> state = world_.saveState();
      const uint64_t hash = world_.stateHash();
      writer_.snapshot(t, hash, state);
      if (check) writer_.check({t, hash});
    } else if (check) {
      writer_.check({t, world_.stateHash()});
    }
  }
  writer_.flush();  // the tick is in the kernel before the next one starts
  return r;
}

void Recorder::finish(const StepResult& last) {
  if (finished_) return;
  finished_ = true;
  sgr::EndInfo e;
  e.tick = world_.tick();
  e.hash = world_.stateHash();
  e.faulted = !last.ok;
  if (!last.ok) e.message = last.error.message();
  writer_.end(e);
}

}  // namespace sg
