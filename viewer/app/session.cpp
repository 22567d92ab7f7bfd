#include "viewer/app/session.h"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "replay/input_file.h"
#include "replay/physics_devices.h"
#include "replay/scenario_files.h"
#include "viewer/app/text.h"

namespace sg::viewer {
namespace {
/// Reads a file a scenario names, relative to `dir` unless absolute, and remembers it for
/// embedding in recordings (what loadScenarioFile does for a file on disk).
ScenarioFileReader relativeReader(const std::string& dir, std::vector<sgr::EmbeddedFile>* files) {
  return [dir, files](const std::string& name, std::vector<uint8_t>* out, std::string* why) {
    namespace fs = std::filesystem;
    const fs::path p = fs::path(name).is_absolute() || dir.empty() ? fs::path(name) : fs::path(dir) / name;
    // The bounded reader (regular files only, never blocks, size checked first), as
    // loadScenarioFile reads the same names.
    std::string expected;
    if (!readInputFile(p.string(), InputLimits::kHeightmapBytes, out, &expected)) {
      *why = "'" + shownText(name) + "' to be " + expected;
      return false;
    }
    files->push_back(sgr::EmbeddedFile{name, *out});
    return true;
  };
}
}  // namespace

std::unique_ptr<Session> Session::load(const std::string& path, int threads) {
  auto s = std::make_unique<Session>();
  s->threads = threads;
  s->scenario = loadScenarioFile(path, &s->files);
  s->scenarioDir = path.empty() ? std::string() : std::filesystem::path(path).parent_path().string();
  s->world = makeWorld(s->scenario, threads, physicalMemoryBytes());
  return s;
}

std::unique_ptr<Session> Session::rebuilt(const std::string& text, bool replayHistory) const {
  auto s = std::make_unique<Session>();
  s->threads = threads;
  s->scenarioDir = scenarioDir;
  s->scenario = parseScenario(text, scenario.sourceName, relativeReader(scenarioDir, &s->files));
  s->world = makeWorld(s->scenario, threads, physicalMemoryBytes());
  if (replayHistory)  // up to the live tick: inputs beyond it (after a step back) are not taken
    for (int64_t t = 0; t < world->tick(); ++t) {
      const StepResult r = s->step(history[t]);
      if (!r.ok)
        throw ScenarioError(scenario.sourceName, "$",
                            "a scenario the session so far replays under (" + r.error.message() + ")");
    }
  return s;
}

StepResult Session::step(const TickInput& input) {
  const int64_t now = world->tick();
  if (now < historyEnd()) {  // a new branch from here: the old future goes, and its snapshots
    history.resize(now);
    while (!snapshots_.empty() && snapshots_.back().first > now) snapshots_.pop_back();
  }
  history.push_back(input);
  if (!recorder) {
    StepResult r = world->step(input, &clock);
    if (r.ok) keepSnapshot();
    return r;
  }
  const int64_t before = world->tick();
  try {
    StepResult r = recorder->step(input, &clock);
    if (r.ok) keepSnapshot();
    return r;
  } catch (const std::exception& e) {
    // A write that failed (a full disk, a file-size limit): the recording ends at its last
    // complete chunk (still readable, as a recording cut off by a crash) and the session goes on
    // unrecorded; the caller shows recordingError. The writer appends the tick's input before
    // stepping and writes after it, so the world has stepped unless the step itself failed.
    recordingError = std::string(e.what()) + " (the recording stopped there, the session goes on)";
    recorder.reset();
    if (world->tick() == before) return world->step(input, &clock);
    return {};
  }
}

StepResult Session::replayNext() {
  const int64_t t = world->tick();
  if (t >= historyEnd()) return {};
  StepResult r = world->step(history[t], &clock);
  if (r.ok) keepSnapshot();
  return r;
}

void Session::keepSnapshot() {
  const int64_t t = world->tick();
  if (t % snapshotEvery_ != 0 || (!snapshots_.empty() && snapshots_.back().first >= t)) return;
  snapshots_.emplace_back(t, world->saveState());
  // Within the budget: at most 64 states, fewer for big worlds (at least 2); beyond it the spacing
  // doubles and every state off the new spacing goes.
  const uint64_t bytes = std::max<uint64_t>(1, snapshots_.back().second.size());
  const size_t keep = size_t(std::clamp<uint64_t>(kLiveSnapshotBytes / bytes, 2, 64));
  while (snapshots_.size() > keep) {
    snapshotEvery_ *= 2;
    std::erase_if(snapshots_, [&](const auto& s) { return s.first % snapshotEvery_ != 0; });
  }
}

bool Session::seek(int64_t t, bool* stopped, std::string* error) {
  *stopped = false;
  t = std::clamp<int64_t>(t, 0, historyEnd());
  if (t == world->tick()) return true;
  if (recorder) {
    if (!stopRecording(error)) return false;
    *stopped = true;
  }
  // The nearest kept state at or before t, unless stepping on from here is shorter.
  const auto snap = std::find_if(snapshots_.rbegin(), snapshots_.rend(), [&](const auto& s) { return s.first <= t; });
  const int64_t from = snap == snapshots_.rend() ? 0 : snap->first;
  if (!(world->tick() <= t && world->tick() >= from)) {
    try {
      if (snap == snapshots_.rend())
        world = makeSessionWorld();
      else
        world->restoreState(snap->second);
    } catch (const std::exception& e) {
      *error = std::string("going back to tick ") + std::to_string(from) + ": " + e.what();
      return false;
    }
  }
  while (world->tick() < t) {
    const StepResult r = world->step(history[world->tick()], &clock);
    if (!r.ok) {
      *error = "replaying the session to tick " + std::to_string(t) + " faulted: " + r.error.message();
      return false;
    }
  }
  return true;
}

std::unique_ptr<SimWorld> Session::makeSessionWorld() const {
  std::unique_ptr<SimWorld> w = makeWorld(scenario, threads, physicalMemoryBytes());
  if (physics != PhysicsPath::Cpu)
    if (const std::string why = applyPhysicsPath(*w, physics); !why.empty())
      throw std::runtime_error(std::string("--physics ") + physicsPathName(physics) + ": " + why);
  return w;
}

std::string Session::setPhysics(PhysicsPath path) {
  if (std::string why = applyPhysicsPath(*world, path); !why.empty()) return why;
  physics = path;
  return "";
}

bool Session::startRecording(const std::string& path, std::string* error) {
  if (recorder) {
    *error = "already recording to " + recordPath;
    return false;
  }
  try {
    std::unique_ptr<SimWorld> fresh = makeSessionWorld();  // it becomes the live world
    RecordSettings settings;
    settings.checkEvery = defaultCheckEvery(fresh->counts().patches());
    auto rec = std::make_unique<Recorder>(path, scenario, files, *fresh, settings);
    // The ticks up to the live world's (after a step back, the inputs beyond it are a future the
    // recording does not take: recording starts a new branch from here).
    const int64_t now = world->tick();
    for (int64_t t = 0; t < now; ++t) {
      const StepResult r = rec->step(history[t]);
      if (!r.ok) {
        *error = "catching up the recording faulted: " + r.error.message();
        return false;
      }
    }
    if (fresh->stateHash() != world->stateHash()) {
      *error = "catching up the recording reached hash " + hex(fresh->stateHash()) + ", the live world has " +
               hex(world->stateHash());
      return false;
    }
    world = std::move(fresh);
    recorder = std::move(rec);
    recordPath = path;
    history.resize(now);
    while (!snapshots_.empty() && snapshots_.back().first > now) snapshots_.pop_back();
    return true;
  } catch (const std::exception& e) {
    // The writer's messages name the file already ("x.sgr: cannot create ..."): not twice.
    const std::string what = e.what();
    *error = what.rfind(path + ":", 0) == 0 ? what : path + ": " + what;
    return false;
  }
}

bool Session::stopRecording(std::string* error) {
  if (!recorder) {
    *error = "not recording";
    return false;
  }
  try {
    recorder->finish();
  } catch (const std::exception& e) {
    *error = recordPath + ": " + e.what();
    recorder.reset();
    return false;
  }
  std::printf("recorded   %" PRId64 " ticks to %s (hash %s)\n", world->tick(), recordPath.c_str(),
              hex(world->stateHash()).c_str());
  std::fflush(stdout);
  recorder.reset();
  return true;
}

void editScenarioJson(nlohmann::json* doc, const std::string& sourceName, const std::string& dotted,
                      const std::string& valueJson) {
  nlohmann::json& j = *doc;
  if (!j.is_object()) throw ScenarioError(sourceName, "$", "a JSON object to edit");
  const std::string where = "$." + shownText(dotted);
  // The path: dotted segments, few and short (each one is a nesting level of the result).
  std::vector<std::string> segments;
  if (dotted.size() > EditLimits::kPathChars)
    throw ScenarioError(sourceName, where,
                        "a path of at most " + std::to_string(EditLimits::kPathChars) + " characters");
  for (size_t at = 0;;) {
    const size_t dot = dotted.find('.', at);
    segments.push_back(dotted.substr(at, dot == std::string::npos ? std::string::npos : dot - at));
    if (segments.back().empty()) throw ScenarioError(sourceName, where, "a dotted path of names (a.b.c)");
    try {  // a name that is not UTF-8 would make every later dump of the scenario throw
      (void)nlohmann::json(segments.back()).dump();
    } catch (const nlohmann::json::exception&) {
      throw ScenarioError(sourceName, where, "a path of UTF-8 names");
    }
    if (dot == std::string::npos) break;
    at = dot + 1;
  }
  if (segments.size() > EditLimits::kPathSegments)
    throw ScenarioError(sourceName, where, "a path of at most " + std::to_string(EditLimits::kPathSegments) + " names");
  // The value: its depth is counted before parsing, so a value 100000 levels deep never reaches
  // nlohmann's recursive code (dump, destructor) and never reaches a message.
  const int budget = EditLimits::kJsonDepth - int(segments.size());
  if (jsonNestingDepth(valueJson, budget) > budget)
    throw ScenarioError(
        sourceName, where,
        "a JSON value nested at most " + std::to_string(budget) + " levels deep, got '" + shownText(valueJson) + "'");
  nlohmann::json v = nlohmann::json::parse(valueJson, nullptr, false);
  if (v.is_discarded()) throw ScenarioError(sourceName, where, "a JSON value, got '" + shownText(valueJson) + "'");
  // Walks the path by hand (not json_pointer, whose "/list/50000000" fills an array with 50 M
  // nulls): objects take any name, arrays an index up to their size (the size appends one).
  nlohmann::json* node = &j;
  for (size_t k = 0; k < segments.size(); ++k) {
    const std::string& name = segments[k];
    if (node->is_null()) *node = nlohmann::json::object();
    if (node->is_object()) {
      node = &(*node)[name];
    } else if (node->is_array()) {
      const size_t size = node->size();
      size_t index = 0;
      bool number = name.size() <= 9;
      for (char c : name) number = number && c >= '0' && c <= '9';
      if (number) index = size_t(std::stoul(name));
      if (!number || index > size)
        throw ScenarioError(sourceName, where,
                            "an index from 0 to " + std::to_string(size) + " at '" + shownText(name) + "'");
      if (index == size) {
        if (size >= EditLimits::kArrayEntries)
          throw ScenarioError(sourceName, where,
                              "a list of at most " + std::to_string(EditLimits::kArrayEntries) + " entries");
        node->push_back(nullptr);
      }
      node = &(*node)[index];
    } else {
      throw ScenarioError(sourceName, where, "a path of objects and lists ('" + shownText(name) + "' is in a value)");
    }
  }
  *node = std::move(v);
  // The grass model has two names (docs/scenario-format.md): setting one replaces the other, so
  // `set particles.model "blade"` works on a scenario written with "constraintMode".
  if (segments.size() == 2 && segments[0] == "particles" && j["particles"].is_object()) {
    if (segments[1] == "model") j["particles"].erase("constraintMode");
    if (segments[1] == "constraintMode") j["particles"].erase("model");
  }
}

std::string editScenarioText(const std::string& text, const std::string& sourceName, const std::string& dotted,
                             const std::string& valueJson) {
  nlohmann::json j = parseScenarioJsonForEdit(text, sourceName);
  editScenarioJson(&j, sourceName, dotted, valueJson);
  return j.dump(2);
}

nlohmann::json parseScenarioJsonForEdit(const std::string& text, const std::string& sourceName) {
  // The live scenario's text was parsed (and bounded) once already; counted again all the same.
  if (jsonNestingDepth(text, EditLimits::kJsonDepth) > EditLimits::kJsonDepth)
    throw ScenarioError(sourceName, "$",
                        "a JSON object nested at most " + std::to_string(EditLimits::kJsonDepth) + " levels deep");
  nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (!j.is_object()) throw ScenarioError(sourceName, "$", "a JSON object to edit");
  return j;
}

}  // namespace sg::viewer
