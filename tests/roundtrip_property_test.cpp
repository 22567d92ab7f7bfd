// Round trips and mutations as properties (RapidCheck): for scenarios drawn at random over the
// scalars, interpolation factors, field sizes, seeds and bodies,
//   - scenario -> world -> state -> restore into a fresh world -> the same hash, the same bytes,
//     and the same hashes for every later tick;
//   - record -> replay -> every recorded hash matches, and the replay ends on the recorded hash;
// and for any mutation (byte flips, cuts, insertions, deletions) of a valid file,
//   - a recording is either refused with a RecordingError / ScenarioError, or replays to hashes
//     that the original run had at the same ticks (a cut-off file replays a prefix);
//   - a saved state is either refused with a StateError, or restores to exactly those bytes;
//   - scenario text is either refused with a ScenarioError or builds a world that steps.
// Nothing else (no other exception, no crash, no hang) is an allowed outcome.
#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "replay/format/sgr_format.h"
#include "replay/recording.h"
#include "sim/world/sim_world.h"
#include "tests/cli_support.h"
#include "tests/test_support.h"

namespace sg {
namespace {
using nlohmann::json;

/// A small scenario drawn from the thesis-bodies scene: 4..10 patches a side, any scalar and
/// interpolation factor, 0..3 of its bodies dropped somewhere over the field, any seed.
std::string genScenarioText() {
  static const json base = [] {
    std::ifstream in(test::sourcePath("scenarios/thesis-bodies.json"));
    return json::parse(in);
  }();
  json j = base;
  static const char* const kScalars[] = {"fx32", "fx16", "float", "double"};
  j["scalar"] = kScalars[*rc::gen::inRange(0, 4)];
  j["seed"] = *rc::gen::inRange(0, 1000);
  const int patches = *rc::gen::inRange(4, 11);
  j["field"]["patchesX"] = patches;
  j["field"]["patchesZ"] = *rc::gen::inRange(4, 11);
  static const int kInterpolation[] = {1, 2, 4};
  j["particles"]["interpolation"] = kInterpolation[*rc::gen::inRange(0, 3)];
  json bodies = json::array();
  const int bodyCount = *rc::gen::inRange(0, 4);
  for (int b = 0; b < bodyCount; ++b) {
    json body = base["bodies"]["list"][size_t(b)];
    // Positions in centimetres (exact in every scalar's decimal reading), over the 1 m field.
    body["position"] = {*rc::gen::inRange(-60, 61) / 100.0, *rc::gen::inRange(30, 200) / 100.0,
                        *rc::gen::inRange(-60, 61) / 100.0};
    bodies.push_back(body);
  }
  j["bodies"]["list"] = bodies;
  // The script names bodies; keep only the commands for bodies still in the list.
  json script = json::array();
  for (const json& c : base["script"]) {
    bool present = !c.contains("body");
    for (const json& b : bodies) present = present || b["name"] == c["body"];
    if (present && c["tick"].get<int64_t>() < 60) script.push_back(c);
  }
  j["script"] = script;
  return j.dump(2);
}

Scenario parse(const std::string& text) { return parseScenario(text, "generated.json", {}); }

/// The hash after every tick 1..ticks of the scenario's scripted input.
std::vector<uint64_t> scriptedHashes(SimWorld& world, const Scenario& s, int64_t ticks) {
  std::vector<uint64_t> hashes;
  for (int64_t t = 0; t < ticks; ++t) {
    if (!world.step(scriptedInput(s, world.tick())).ok) break;
    hashes.push_back(world.stateHash());
  }
  return hashes;
}

/// One random edit of `bytes`: flip bits, overwrite a run, cut, insert or delete a range.
std::vector<uint8_t> mutate(std::vector<uint8_t> bytes) {
  const int edits = *rc::gen::inRange(1, 4);
  for (int e = 0; e < edits && !bytes.empty(); ++e) {
    const size_t at = *rc::gen::inRange<size_t>(0, bytes.size());
    switch (*rc::gen::inRange(0, 5)) {
      case 0:
        bytes[at] ^= uint8_t(1u << *rc::gen::inRange(0, 8));
        break;
      case 1: {
        const size_t n = std::min<size_t>(bytes.size() - at, *rc::gen::inRange<size_t>(1, 9));
        for (size_t i = 0; i < n; ++i) bytes[at + i] = *rc::gen::arbitrary<uint8_t>();
        break;
      }
      case 2:
        bytes.resize(at);
        break;
      case 3: {
        const std::vector<uint8_t> extra =
            *rc::gen::container<std::vector<uint8_t>>(*rc::gen::inRange<size_t>(1, 9), rc::gen::arbitrary<uint8_t>());
        bytes.insert(bytes.begin() + std::ptrdiff_t(at), extra.begin(), extra.end());
        break;
      }
      default: {
        const size_t n = std::min<size_t>(bytes.size() - at, *rc::gen::inRange<size_t>(1, 64));
        bytes.erase(bytes.begin() + std::ptrdiff_t(at), bytes.begin() + std::ptrdiff_t(at + n));
      }
    }
  }
  return bytes;
}

// RapidCheck's default of 100 cases; each builds and steps a world, a few ms to a few tens of ms.

RC_GTEST_PROP(RoundTripProperty, SaveRestoreGivesTheSameStateAndTheSameFuture, ()) {
  const Scenario s = parse(genScenarioText());
  const int64_t before = *rc::gen::inRange(0, 40), after = *rc::gen::inRange(1, 20);
  auto original = makeWorld(s);
  scriptedHashes(*original, s, before);
  const std::vector<uint8_t> saved = original->saveState();
  auto restored = makeWorld(s);
  restored->restoreState(saved);
  RC_ASSERT(restored->tick() == original->tick());
  RC_ASSERT(restored->stateHash() == original->stateHash());
  RC_ASSERT(restored->saveState() == saved);
  RC_ASSERT(scriptedHashes(*restored, s, after) == scriptedHashes(*original, s, after));
}

RC_GTEST_PROP(RoundTripProperty, RecordThenReplayMatchesEveryHash, ()) {
  const Scenario s = parse(genScenarioText());
  TempDir dir;
  const std::string path = dir.file("p.sgr");
  RecordingSettings settings;
  settings.checkEvery = uint32_t(*rc::gen::inRange(0, 4));
  settings.snapshotEvery = uint32_t(*rc::gen::inRange(0, 8));
  const int64_t ticks = *rc::gen::inRange(1, 40);
  RecordingSummary summary;
  {
    RecordingSession session = RecordingSession::fromScenario(s, path, settings);
    session.stepScripted(ticks);
    summary = session.finish();
  }
  const VerifyResult v = verifyRecording(path);
  RC_ASSERT(v.ok);
  RC_ASSERT(v.ticks == summary.ticks);
  RC_ASSERT(v.finalHash == summary.finalHash);
  RC_ASSERT(v.hashesChecked >= 1);  // END's hash at least
}

/// One recording and the hash of every tick of its run, shared by the mutation property.
struct ReferenceRecording {
  TempDir dir;
  std::vector<uint8_t> bytes;
  std::map<int64_t, uint64_t> hashAtTick;
};

const ReferenceRecording& reference() {
  static const ReferenceRecording* ref = [] {
    auto* r = new ReferenceRecording;
    const std::string path = r->dir.file("ref.sgr");
    RecordingSettings settings;
    settings.checkEvery = 3;
    settings.snapshotEvery = 8;
    RecordingSession session =
        RecordingSession::fromScenarioFile(test::sourcePath("scenarios/thesis-bodies.json"), path, settings);
    r->hashAtTick[0] = session.stateHash();
    for (int t = 0; t < 30; ++t) {
      session.stepScripted(1);
      r->hashAtTick[session.tick()] = session.stateHash();
    }
    session.finish();
    r->bytes = readBytes(path);
    return r;
  }();
  return *ref;
}

RC_GTEST_PROP(MutationProperty, AMutatedRecordingIsRefusedOrReplaysTheOriginalRun, ()) {
  const ReferenceRecording& ref = reference();
  TempDir dir;
  const std::string path = dir.file("m.sgr");
  writeBytes(path, mutate(ref.bytes));
  VerifyResult v;
  try {
    v = verifyRecording(path);
  } catch (const sgr::RecordingError&) {
    RC_TAG("refused");
    return;  // refused, with the byte offset
  } catch (const ScenarioError&) {
    RC_TAG("scenario refused");
    return;  // the embedded scenario no longer parses
  }
  RC_TAG(v.ok ? "replayed" : "mismatch reported");
  if (!v.ok) {
    // A mismatch the replay itself reported is a detection, not a silent run, as long as it names
    // the tick and the hashes that differ (or the fault).
    RC_ASSERT(v.firstMismatchTick >= 0 || !v.error.empty());
    return;
  }
  const auto it = ref.hashAtTick.find(v.ticks);
  RC_ASSERT(it != ref.hashAtTick.end());
  RC_ASSERT(v.finalHash == it->second);
}

RC_GTEST_PROP(MutationProperty, AMutatedStateIsRefusedOrRestoredExactly, ()) {
  const Scenario s = parse(genScenarioText());
  auto world = makeWorld(s);
  scriptedHashes(*world, s, *rc::gen::inRange(0, 20));
  const std::vector<uint8_t> mutated = mutate(world->saveState());
  auto fresh = makeWorld(s);
  try {
    fresh->restoreState(mutated);
  } catch (const StateError&) {
    RC_TAG("refused");
    return;
  }
  RC_TAG("restored");
  // Accepted: the state is what the bytes say, nothing normalised away or ignored.
  RC_ASSERT(fresh->saveState() == mutated);
}

RC_GTEST_PROP(MutationProperty, MutatedScenarioTextIsRefusedOrBuildsAWorldThatSteps, ()) {
  const std::string text = genScenarioText();
  const std::vector<uint8_t> mutated = mutate(std::vector<uint8_t>(text.begin(), text.end()));
  std::unique_ptr<SimWorld> world;
  Scenario s;
  try {
    s = parse(std::string(mutated.begin(), mutated.end()));
    world = makeWorld(s, 1, uint64_t(1) << 30);
  } catch (const ScenarioError& e) {
    RC_ASSERT(std::string(e.what()).find('\n') == std::string::npos);
    RC_TAG("refused");
    return;
  }
  RC_TAG("built");
  // A world that was built steps, or stops on a reported fault; nothing throws.
  for (int t = 0; t < 5; ++t) {
    const StepResult r = world->step(scriptedInput(s, world->tick()));
    if (!r.ok) {
      RC_ASSERT(!r.error.message().empty());
      break;
    }
  }
}

/// Every path to a number in `j` (objects and arrays), as JSON pointers.
void numberPointers(const json& j, const json::json_pointer& at, std::vector<json::json_pointer>* out) {
  if (j.is_number()) out->push_back(at);
  if (j.is_object())
    for (auto it = j.begin(); it != j.end(); ++it) numberPointers(*it, at / it.key(), out);
  if (j.is_array())
    for (size_t i = 0; i < j.size(); ++i) numberPointers(j[i], at / i, out);
}

RC_GTEST_PROP(MutationProperty, AnExtremeValueInAnyNumberIsRefusedOrSteps, ()) {
  // The values at and around every scalar's limits, for whichever field is drawn: each must be
  // refused at load (with its path) or give a world whose faults are reported by the step.
  json j = json::parse(genScenarioText());
  std::vector<json::json_pointer> numbers;
  numberPointers(j, json::json_pointer(), &numbers);
  RC_PRE(!numbers.empty());
  const json::json_pointer target = numbers[*rc::gen::inRange<size_t>(0, numbers.size())];
  static const char* const kExtremes[] = {"0",
                                          "-1",
                                          "1e-30",
                                          "1e30",
                                          "-1e30",
                                          "32767",
                                          "32768",
                                          "-32769",
                                          "65536",
                                          "2147483647",
                                          "2147483648",
                                          "-2147483649",
                                          "9223372036854775807",
                                          "1e-9",
                                          "123456.789"};
  const std::string value = kExtremes[*rc::gen::inRange<size_t>(0, std::size(kExtremes))];
  j[target] = json::parse(value);
  std::string text = j.dump();
  RC_TAG(target.to_string());
  std::unique_ptr<SimWorld> world;
  Scenario s;
  try {
    s = parse(text);
    world = makeWorld(s, 1, uint64_t(1) << 30);
  } catch (const ScenarioError& e) {
    RC_ASSERT(std::string(e.what()).find('\n') == std::string::npos);
    return;
  }
  for (int t = 0; t < 5; ++t)
    if (!world->step(scriptedInput(s, world->tick())).ok) break;
}

}  // namespace
}  // namespace sg
