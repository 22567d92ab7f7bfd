#include "viewer/app/session.h"

#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

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
    std::error_code ec;
    if (!fs::is_regular_file(p, ec)) {
      *why = "an existing file, '" + p.string() + "' was not found";
      return false;
    }
    std::ifstream in(p, std::ios::binary);
    if (!in) {
      *why = "a readable file, '" + p.string() + "'";
      return false;
    }
    out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
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
  if (replayHistory)
    for (const TickInput& in : history) {
      const StepResult r = s->step(in);
      if (!r.ok)
        throw ScenarioError(scenario.sourceName, "$",
                            "a scenario the session so far replays under (" + r.error.message() + ")");
    }
  return s;
}

StepResult Session::step(const TickInput& input) {
  history.push_back(input);
  return recorder ? recorder->step(input, &clock) : world->step(input, &clock);
}

bool Session::startRecording(const std::string& path, std::string* error) {
  if (recorder) {
    *error = "already recording to " + recordPath;
    return false;
  }
  try {
    std::unique_ptr<SimWorld> fresh = makeWorld(scenario, threads, physicalMemoryBytes());
    RecordSettings settings;
    settings.checkEvery = defaultCheckEvery(fresh->counts().patches());
    auto rec = std::make_unique<Recorder>(path, scenario, files, *fresh, settings);
    for (const TickInput& in : history) {
      const StepResult r = rec->step(in);
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
    return true;
  } catch (const std::exception& e) {
    *error = path + ": " + e.what();
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

std::string editScenarioText(const std::string& text, const std::string& sourceName, const std::string& dotted,
                             const std::string& valueJson) {
  nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (!j.is_object()) throw ScenarioError(sourceName, "$", "a JSON object to edit");
  nlohmann::json v = nlohmann::json::parse(valueJson, nullptr, false);
  if (v.is_discarded()) throw ScenarioError(sourceName, "$." + dotted, "a JSON value, got '" + valueJson + "'");
  std::string pointer;
  for (char c : dotted) pointer += c == '.' ? '/' : c;
  try {
    j[nlohmann::json::json_pointer("/" + pointer)] = v;
  } catch (const nlohmann::json::exception&) {
    throw ScenarioError(sourceName, "$." + dotted, "a path of objects");
  }
  return j.dump(2);
}

}  // namespace sg::viewer
