#include "replay/cli/sweep_shards.h"

#include "replay/cli/sweep_shard_format.h"

#include <xxhash.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "replay/cli/cli_common.h"
#include "replay/input_file.h"
#include "replay/output_file.h"
#include "replay/progress.h"
#include "replay/recorder.h"
#include "replay/scenario_files.h"
#include "sim/scenario/json_bounds.h"
#include "sim/state/byte_order.h"

namespace sg::sweep {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kPlanFormat = "simgrass-sweep-plan/1";
constexpr const char* kShardFormat = "simgrass-sweep-shard/1";
constexpr uint64_t kPlanBytes = uint64_t(16) << 20;
constexpr const char* kPlanCopy = "plan.json";

std::string hex64(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
  return buf;
}

/// Doubles travel as their IEEE bits: exact, and NaN (a faulted measure) survives JSON.
uint64_t bitsOf(double v) {
  uint64_t u;
  std::memcpy(&u, &v, sizeof u);
  return u;
}
double fromBits(uint64_t u) {
  double v;
  std::memcpy(&v, &u, sizeof v);
  return v;
}

json optionsJson(const Options& o) {
  return {{"scenarios", o.scenarios},
          {"scalars", o.scalars},
          {"k", o.ks},
          {"dt", o.dts},
          {"lod", o.lods},
          {"broadphase", o.broadphases},
          {"models", o.models},
          {"physics", o.physics},
          {"seconds", o.seconds},
          {"repeats", o.repeats},
          {"threads", o.threads}};
}

template <class T>
T field(const json& j, const char* key, const std::string& file, const std::string& at) {
  const std::string where = at + "." + key;
  if (!j.is_object() || !j.contains(key)) failInput(file, where, "a value (missing)");
  const json& v = j[key];
  if constexpr (std::is_same_v<T, std::string>) {
    if (!v.is_string()) failInput(file, where, "a string");
  } else if constexpr (std::is_same_v<T, bool>) {
    if (!v.is_boolean()) failInput(file, where, "true or false");
  } else if constexpr (std::is_floating_point_v<T>) {
    if (!v.is_number()) failInput(file, where, "a number");
  } else {
    if (!v.is_number_integer()) failInput(file, where, "an integer");
  }
  return v.get<T>();
}

Options optionsFrom(const json& j, const std::string& file) {
  Options o;
  const std::string at = "$.options";
  o.scenarios = field<std::string>(j, "scenarios", file, at);
  o.scalars = field<std::string>(j, "scalars", file, at);
  o.ks = field<std::string>(j, "k", file, at);
  o.dts = field<std::string>(j, "dt", file, at);
  o.lods = field<std::string>(j, "lod", file, at);
  o.broadphases = field<std::string>(j, "broadphase", file, at);
  o.models = field<std::string>(j, "models", file, at);
  o.physics = j.contains("physics") ? field<std::string>(j, "physics", file, at) : "cpu";  // older plans: none
  o.seconds = field<double>(j, "seconds", file, at);
  o.repeats = int(field<int64_t>(j, "repeats", file, at));
  o.threads = int(field<int64_t>(j, "threads", file, at));
  if (!(o.seconds >= 1e-3 && o.seconds <= 3600)) failInput(file, at + ".seconds", "1e-3 to 3600 s");
  if (o.repeats < 1 || o.repeats > 100) failInput(file, at + ".repeats", "1 to 100");
  if (o.threads < 1 || o.threads > 256) failInput(file, at + ".threads", "1 to 256");
  return o;
}

// ---- bytes ----------------------------------------------------------------------------------

/// Reads and checks a shard file. Throws std::runtime_error ("file: byte N: expected ...").
Shard readShard(const std::string& path, uint64_t maxPayload, bool withPayload = true) {
  std::vector<uint8_t> b;
  std::string expected;
  if (!readInputFile(path, InputLimits::kRecordingBytes, &b, &expected)) failInput(path, "byte 0", expected);
  return parseShard(b, path, maxPayload, withPayload);
}

/// The most a reference payload of this plan can hold (a damaged size field cannot ask for more).
/// The most scenario s's reference payload can hold: its observations (three doubles a patch and
/// seven a body, at every compared time) and its recording (the scenario text and files, an
/// input chunk a tick, a chunk per scripted command), twice over. A size field claiming more is
/// refused before anything is allocated (a forged zstd frame cannot make a job zero-fill 17 GB).
uint64_t maxPayloadBytes(const Plan& plan, size_t s) {
  const ScenarioRun& sc = plan.scenarios[s];
  const uint64_t patches = uint64_t(sc.reference.field.patchesX) * uint64_t(sc.reference.field.patchesZ);
  const uint64_t states = uint64_t(plan.ticks / plan.interval + 1);
  const uint64_t observations = states * (40 + 8 * (3 * patches + 7 * uint64_t(kMaxBodies) + 5));
  uint64_t recording = (uint64_t(64) << 10) + sc.reference.text.size() + uint64_t(plan.ticks) * 128 +
                       uint64_t(sc.reference.script.size()) * 64;
  for (const sgr::EmbeddedFile& f : sc.files) recording += f.name.size() + f.bytes.size() + 64;
  return 2 * (observations + recording) + 16;
}

json summaryFields(const DivergenceSummary& s) {
  return {{"ticks", s.ticks},
          {"tipMax", bitsOf(s.tipMax)},
          {"tipMaxTick", s.tipMaxTick},
          {"tipSumSquares", bitsOf(s.tipSumSquares)},
          {"bodyPosMax", bitsOf(s.bodyPosMax)},
          {"bodyAngleMax", bitsOf(s.bodyAngleMax)},
          {"contactDeltaMax", s.contactDeltaMax},
          {"firstObservedTick", s.firstObservedTick},
          {"firstHashTick", s.firstHashTick}};
}

/// A count or tick from a shard, within [lo, hi].
int64_t ranged(const json& j, const char* key, const std::string& file, const std::string& at, int64_t lo, int64_t hi) {
  const int64_t v = field<int64_t>(j, key, file, at);
  if (v < lo || v > hi)
    failInput(file, at + "." + key,
              "a value from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got " + std::to_string(v));
  return v;
}

/// A length or angle from a shard: its bits, a value >= 0 or NaN (a measure of a faulted run).
double measure(const json& j, const char* key, const std::string& file, const std::string& at) {
  const double v = fromBits(field<uint64_t>(j, key, file, at));
  if (!(v >= 0) && !std::isnan(v)) failInput(file, at + "." + key, "a measure >= 0 (or NaN)");
  return v;
}

/// The summary a variant's shard holds, every field within what this plan's runs can give.
DivergenceSummary summaryFrom(const json& j, const std::string& file, const Plan& plan) {
  const std::string at = "$.summary";
  const int64_t states = plan.ticks / plan.interval + 1;
  DivergenceSummary s;
  s.ticks = ranged(j, "ticks", file, at, 0, states);
  s.tipMax = measure(j, "tipMax", file, at);
  s.tipMaxTick = ranged(j, "tipMaxTick", file, at, -1, plan.ticks);
  s.tipSumSquares = measure(j, "tipSumSquares", file, at);
  s.bodyPosMax = measure(j, "bodyPosMax", file, at);
  s.bodyAngleMax = measure(j, "bodyAngleMax", file, at);
  s.contactDeltaMax = ranged(j, "contactDeltaMax", file, at, 0, int64_t(1) << 32);
  s.firstObservedTick = ranged(j, "firstObservedTick", file, at, -1, plan.ticks);
  s.firstHashTick = ranged(j, "firstHashTick", file, at, -1, plan.ticks);
  return s;
}

json modelErrorJson(const ModelError& e) {
  return {bitsOf(e.tipRms), bitsOf(e.tipMax), bitsOf(e.seconds), bitsOf(e.bodyRms), bitsOf(e.bodyMax)};
}

/// The longest fault message a variant's shard may carry (bytes).
constexpr size_t kMaxFaultBytes = 1024;

/// The reference results of scenario `s` from its shard's header and payload.
void takeReference(Plan& plan, size_t s, const Shard& shard, const std::string& file, bool withObservations) {
  ScenarioRun& sc = plan.scenarios[s];
  const json& h = shard.header;
  // A world's patches are at most its field's (fewer with a level-of-detail window), at least one.
  sc.patches = ranged(h, "patches", file, "$", 1, sc.reference.field.patchesX * sc.reference.field.patchesZ);
  sc.bodies = ranged(h, "bodies", file, "$", 0, kMaxBodies);
  const int64_t states = plan.ticks / plan.interval + 1;
  sc.statesCompared = ranged(h, "statesCompared", file, "$", states, states);
  const json& b = h.value("behaviour", json());
  sc.behaviour.swayStart = fromBits(field<uint64_t>(b, "swayStart", file, "$.behaviour"));
  sc.behaviour.swayLate = fromBits(field<uint64_t>(b, "swayLate", file, "$.behaviour"));
  sc.behaviour.settleAfterGust = fromBits(field<uint64_t>(b, "settleAfterGust", file, "$.behaviour"));
  sc.behaviour.settleAfterPress = fromBits(field<uint64_t>(b, "settleAfterPress", file, "$.behaviour"));
  sc.behaviour.downAfterPress = fromBits(field<uint64_t>(b, "downAfterPress", file, "$.behaviour"));
  const json& m = h.value("modelError", json());
  for (const Rational& dt : plan.axes.dts) {
    const std::string key = dt.toString();
    const char* expected = "five numbers (the model error at this dt)";
    if (!m.is_object() || !m.contains(key) || !m[key].is_array() || m[key].size() != 5)
      failInput(file, "$.modelError." + key, expected);
    for (const json& v : m[key])
      if (!v.is_number_unsigned()) failInput(file, "$.modelError." + key, expected);
    const auto number = [&](size_t k) { return fromBits(m[key][k].get<uint64_t>()); };
    sc.modelError[key] = {number(0), number(1), number(2), number(3), number(4), {NAN, NAN}, {}};
  }
  for (Row& r : plan.rows)
    if (r.scenario == s) r.modelError = sc.modelError.at(r.settings.timeStep->toString());
  if (withObservations) readReferencePayload(shard.payload, file, &sc.recording, &sc.observed);
}

/// Checks that a shard belongs to this plan and is the job its header says; returns the job.
int64_t shardJob(const Plan& plan, const std::string& fingerprint, const Shard& s, const std::string& file) {
  if (s.header.value("format", std::string()) != kShardFormat)
    failInput(file, "$.format", std::string("'") + kShardFormat + "'");
  const std::string theirs = s.header.value("fingerprint", std::string());
  if (theirs != fingerprint)
    failInput(file, "$.fingerprint",
              "a shard of this plan (fingerprint " + fingerprint + "), got one of plan '" + theirs.substr(0, 40) + "'");
  const int64_t job = field<int64_t>(s.header, "job", file, "$");
  if (job < 0 || job >= jobCount(plan))
    failInput(file, "$.job", "a job from 0 to " + std::to_string(jobCount(plan) - 1) + ", got " + std::to_string(job));
  const std::string kind = field<std::string>(s.header, "kind", file, "$");
  if (kind != (job < referenceJobs(plan) ? "reference" : "variant"))
    failInput(file, "$.kind",
              std::string(job < referenceJobs(plan) ? "reference" : "variant") + " for job " + std::to_string(job));
  return job;
}
}  // namespace

std::string fingerprintOf(const Plan& plan) {
  XXH3_state_t* st = XXH3_createState();
  XXH3_64bits_reset(st);
  auto add = [&](const void* p, size_t n) {
    const uint64_t size = n;
    XXH3_64bits_update(st, &size, sizeof size);
    XXH3_64bits_update(st, p, n);
  };
  const std::string build = buildId(), options = optionsJson(plan.options).dump();
  add(build.data(), build.size());
  add(options.data(), options.size());
  for (const ScenarioRun& sc : plan.scenarios) {
    add(sc.reference.text.data(), sc.reference.text.size());
    for (const sgr::EmbeddedFile& f : sc.files) {
      add(f.name.data(), f.name.size());
      add(f.bytes.data(), f.bytes.size());
    }
  }
  const uint64_t h = XXH3_64bits_digest(st);
  XXH3_freeState(st);
  return hex64(h);
}

std::string jobName(const Plan& plan, int64_t job) {
  if (job < referenceJobs(plan)) return "the reference of " + plan.scenarios[size_t(job)].name;
  const Row& r = plan.rows[size_t(job - referenceJobs(plan))];
  return plan.scenarios[r.scenario].name + ": " + r.settingsText();
}

std::string shardPath(const std::string& dir, int64_t job) {
  char name[32];
  std::snprintf(name, sizeof name, "shard-%06" PRId64 ".sgs", job);
  return (fs::path(dir) / name).string();
}

bool writePlan(const Plan& plan, const std::string& path) {
  json jobs = json::array();
  for (int64_t j = 0; j < jobCount(plan); ++j) {
    const bool ref = j < referenceJobs(plan);
    json job = {{"job", j}, {"kind", ref ? "reference" : "variant"}};
    if (ref) {
      job["scenario"] = plan.scenarios[size_t(j)].name;
      job["file"] = plan.scenarios[size_t(j)].file;
    } else {
      const Row& r = plan.rows[size_t(j - referenceJobs(plan))];
      job["scenario"] = plan.scenarios[r.scenario].name;
      job["settings"] = r.settingsText();
      job["needs"] = int64_t(r.scenario);  // its scenario's reference job
    }
    jobs.push_back(std::move(job));
  }
  json scenarios = json::array();  // what a merge needs of them (it reads no scenario file)
  for (const ScenarioRun& sc : plan.scenarios)
    scenarios.push_back(
        {{"file", sc.file}, {"name", sc.name}, {"model", grassModelName(sc.model)}, {"inputs", sc.inputs}});
  const json doc = {{"format", kPlanFormat},
                    {"build", buildId()},
                    {"fingerprint", fingerprintOf(plan)},
                    {"options", optionsJson(plan.options)},
                    {"scenarios", std::move(scenarios)},
                    {"references", {0, referenceJobs(plan) - 1}},
                    {"variants", {referenceJobs(plan), jobCount(plan) - 1}},
                    {"jobs", std::move(jobs)}};
  std::string error;
  if (!writeFileAtomic(path, doc.dump(2, ' ', false, json::error_handler_t::replace) + "\n", &error)) {
    printError("simgrass sweep: %s\n", error.c_str());
    return false;
  }
  return true;
}

namespace {
/// A plan file's JSON, its format and build checked.
json planDocument(const std::string& path) {
  std::string text, expected;
  if (!readInputFile(path, kPlanBytes, &text, &expected)) failInput(path, "$", expected);
  json doc = json::parse(text, nullptr, false);
  if (!doc.is_object()) failInput(path, "$", "a sweep plan (JSON, written by simgrass sweep --plan)");
  if (doc.value("format", std::string()) != kPlanFormat)
    failInput(path, "$.format", std::string("'") + kPlanFormat + "'");
  const std::string build = field<std::string>(doc, "build", path, "$");
  if (build != buildId())
    failInput(path, "$.build", "a plan of this build ('" + buildId() + "'), got '" + build.substr(0, 80) + "'");
  return doc;
}
}  // namespace

Plan readPlanForMerge(const std::string& path, std::string* fingerprint) {
  const json doc = planDocument(path);
  const Options o = optionsFrom(doc.value("options", json()), path);
  *fingerprint = field<std::string>(doc, "fingerprint", path, "$");
  const json& list = doc.value("scenarios", json());
  if (!list.is_array() || list.empty() || list.size() > 100000)
    failInput(path, "$.scenarios", "the plan's scenarios (a non-empty list)");
  std::vector<ScenarioRun> scenarios;
  for (size_t k = 0; k < list.size(); ++k) {
    const std::string at = "$.scenarios[" + std::to_string(k) + "]";
    ScenarioRun sc;
    sc.file = field<std::string>(list[k], "file", path, at);
    sc.name = field<std::string>(list[k], "name", path, at);
    const std::string model = field<std::string>(list[k], "model", path, at);
    try {
      sc.model = *VariantSettings::parse("model=" + model).model;
    } catch (const std::invalid_argument&) {
      failInput(path, at + ".model", "thesis, pbd or blade");
    }
    const json& inputs = list[k].value("inputs", json());
    if (!inputs.is_array() || inputs.size() > 10000) failInput(path, at + ".inputs", "a list of file names");
    for (const json& f : inputs) {
      if (!f.is_string()) failInput(path, at + ".inputs", "a list of file names");
      sc.inputs.push_back(f.get<std::string>());
    }
    scenarios.push_back(std::move(sc));
  }
  Plan plan;
  try {
    plan = planSkeleton(o, std::move(scenarios));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": $.options: " + e.what());
  }
  // The scenarios as the options list them (under each model): one entry each, in that order.
  const size_t expected = splitList(o.scenarios).size() * plan.axes.models.size();
  if (plan.scenarios.size() != expected)
    failInput(path, "$.scenarios",
              std::to_string(expected) + " scenarios (the options' files under their models), got " +
                  std::to_string(plan.scenarios.size()));
  return plan;
}

Plan readPlan(const std::string& path, std::string* fingerprint) {
  const json doc = planDocument(path);
  const Options o = optionsFrom(doc.value("options", json()), path);
  Plan plan;
  try {
    plan = makePlan(o, false, " (paths in a plan are relative to the folder it was written in: run jobs there)");
  } catch (const std::exception& e) {  // ScenarioError, std::invalid_argument
    throw std::runtime_error(path + ": $.options: " + e.what());
  }
  const std::string want = field<std::string>(doc, "fingerprint", path, "$");
  *fingerprint = fingerprintOf(plan);
  if (want != *fingerprint)
    failInput(path, "$.fingerprint",
              "the inputs the plan was made from (fingerprint " + want.substr(0, 40) + "), got " + *fingerprint +
                  ": a scenario or a file it reads changed since");
  return plan;
}

int64_t jobIndex(const std::string& text, int64_t offset, int64_t jobs) {
  int64_t index = -1;
  std::string from = "--job";
  auto number = [](const std::string& s, int64_t* v) {
    if (s.empty() || s.size() > 12 || s.find_first_not_of("0123456789") != std::string::npos) return false;
    *v = std::stoll(s);
    return true;
  };
  if (text == "env") {
    static constexpr const char* kVars[] = {"SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX", "PARALLEL_SEQ"};
    for (const char* var : kVars) {
      const char* v = std::getenv(var);
      if (!v) continue;
      from = var;
      if (!number(v, &index) || (from == "PARALLEL_SEQ" && index < 1))
        throw std::invalid_argument(std::string("--job env: ") + var + ": expected a job index, got '" +
                                    std::string(v).substr(0, 40) + "'");
      if (from == "PARALLEL_SEQ") index -= 1;  // GNU parallel counts from 1
      break;
    }
    if (index < 0)
      throw std::invalid_argument(
          "--job env: expected SLURM_ARRAY_TASK_ID, JOB_COMPLETION_INDEX or PARALLEL_SEQ in the environment, got none");
  } else if (!number(text, &index)) {
    throw std::invalid_argument("--job: expected a job index or 'env', got '" + text.substr(0, 40) + "'");
  }
  index += offset;
  if (index < 0 || index >= jobs)
    throw std::invalid_argument(from + (offset ? " + --job-offset" : "") + ": expected a job from 0 to " +
                                std::to_string(jobs - 1) + ", got " + std::to_string(index));
  return index;
}

int runJob(Plan& plan, const std::string& fingerprint, int64_t job, const std::string& dir, bool quiet) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir, ec)) {
    printError("simgrass sweep: --out %s: expected a folder for the shards (or one that can be created)\n",
               dir.c_str());
    return kExitBadInput;
  }
  // One folder, one plan: a copy of another plan there would make the merge refuse every shard.
  const std::string planCopy = (fs::path(dir) / kPlanCopy).string();
  if (fs::exists(planCopy, ec) || fs::is_symlink(planCopy, ec)) {
    std::string theirs;
    try {
      (void)readPlanForMerge(planCopy, &theirs);
    } catch (const std::exception&) {
      theirs = "";  // not a plan of this build: named below
    }
    if (theirs != fingerprint) {
      printError(
          "simgrass sweep: %s: expected this plan's copy (fingerprint %s), got %s: shards of two plans "
          "in one folder (give each plan a folder of its own)\n",
          planCopy.c_str(), fingerprint.c_str(), theirs.empty() ? "something else" : ("plan " + theirs).c_str());
      return kExitBadInput;
    }
  }
  json header = {{"format", kShardFormat}, {"fingerprint", fingerprint}, {"job", job}, {"name", jobName(plan, job)}};
  std::vector<uint8_t> payload;
  if (job < referenceJobs(plan)) {
    const size_t s = size_t(job);
    std::map<std::string, std::vector<std::array<double, 3>>> cache;
    try {
      measureTuft(plan, s, &cache);
      runReference(plan, s);
    } catch (const std::exception& e) {
      printError("simgrass sweep: job %" PRId64 " (%s): %s\n", job, jobName(plan, job).c_str(), e.what());
      return kExitMismatch;
    }
    const ScenarioRun& sc = plan.scenarios[s];
    json errors = json::object();
    for (const auto& [dt, e] : sc.modelError) errors[dt] = modelErrorJson(e);
    header["kind"] = "reference";
    header["patches"] = sc.patches;
    header["bodies"] = sc.bodies;
    header["statesCompared"] = sc.statesCompared;
    header["behaviour"] = {{"swayStart", bitsOf(sc.behaviour.swayStart)},
                           {"swayLate", bitsOf(sc.behaviour.swayLate)},
                           {"settleAfterGust", bitsOf(sc.behaviour.settleAfterGust)},
                           {"settleAfterPress", bitsOf(sc.behaviour.settleAfterPress)},
                           {"downAfterPress", bitsOf(sc.behaviour.downAfterPress)}};
    header["modelError"] = std::move(errors);
    payload = referencePayload(*sc.recording, sc.observed);
  } else {
    Row& row = plan.rows[size_t(job - referenceJobs(plan))];
    const int64_t refJob = int64_t(row.scenario);
    try {  // the reference of its scenario, from its shard: computed once, by its own job
      const std::string refFile = shardPath(dir, refJob);
      const Shard ref = readShard(refFile, maxPayloadBytes(plan, row.scenario));
      if (shardJob(plan, fingerprint, ref, refFile) != refJob)
        failInput(refFile, "$.job", "job " + std::to_string(refJob));
      takeReference(plan, row.scenario, ref, refFile, true);
    } catch (const std::exception& e) {
      printError("simgrass sweep: job %" PRId64 " needs the reference shard of job %" PRId64
                 " (run that job first, or again): %s\n",
                 job, refJob, e.what());
      return kExitBadInput;
    }
    ProgressBar bar("job " + std::to_string(job), plan.ticks * plan.options.repeats, !quiet);
    for (int rep = 0; rep < plan.options.repeats && row.fault.empty(); ++rep)
      runVariant(plan, row, rep == 0, [&](int64_t t) { bar.update(rep * plan.ticks + t); });
    bar.finish();
    json runMs = json::array();
    for (double ms : row.runMs) runMs.push_back(bitsOf(ms));
    header["kind"] = "variant";
    header["steps"] = row.steps;
    header["runMs"] = std::move(runMs);
    header["fault"] = row.fault;
    header["summary"] = summaryFields(row.summary);
  }
  // The plan beside the shards, for the merge (checked above: missing, or this plan's).
  std::string error;
  try {
    const std::vector<uint8_t> bytes = shardBytes(header, payload);
    if (!writeFileAtomic(shardPath(dir, job), bytes, &error)) {
      printError("simgrass sweep: %s\n", error.c_str());
      return kExitMismatch;
    }
  } catch (const std::exception& e) {
    printError("simgrass sweep: job %" PRId64 ": %s\n", job, e.what());
    return kExitMismatch;
  }
  if (!fs::exists(planCopy, ec) && !writePlan(plan, planCopy)) return kExitMismatch;
  if (!quiet)
    std::printf("job %" PRId64 " (%s): wrote %s\n", job, jobName(plan, job).c_str(), shardPath(dir, job).c_str());
  return kExitOk;
}

bool mergeShards(Plan& plan, const std::string& fingerprint, const std::string& dir, std::string* error) {
  std::vector<std::string> files;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().extension() == ".sgs") files.push_back(it->path().string());
  if (ec) {
    *error = dir + ": expected a folder of shards (" + ec.message() + ")";
    return false;
  }
  std::sort(files.begin(), files.end());
  std::vector<std::string> fileOf(size_t(jobCount(plan)));
  try {
    for (const std::string& file : files) {
      // Headers first (a variant's result is its header); a reference's observations are not
      // needed by the report and stay in its payload.
      const Shard s = readShard(file, 0, false);  // headers only: the payloads stay unread
      const int64_t job = shardJob(plan, fingerprint, s, file);
      std::string& seen = fileOf[size_t(job)];
      if (!seen.empty()) {
        *error = "job " + std::to_string(job) + " (" + jobName(plan, job) + "): two shards, ";
        error->append(seen).append(" and ").append(file);
        return false;
      }
      seen = file;
      if (job < referenceJobs(plan)) {
        takeReference(plan, size_t(job), s, file, false);
        continue;
      }
      Row& row = plan.rows[size_t(job - referenceJobs(plan))];
      // A variant steps at most dt_ref / dt_min = 1/240 / 1e-5 own ticks per reference tick.
      row.steps = ranged(s.header, "steps", file, "$", 0, plan.ticks * 420);
      // A job writes its world's one-line error here (under 200 bytes); a shard's text reaches the
      // terminal and sweep.csv, so a control character or a page of text in it is refused, not
      // printed (an independent pass merged a fault with a newline and a colour escape).
      row.fault = field<std::string>(s.header, "fault", file, "$");
      if (row.fault.size() > kMaxFaultBytes || escapeControl(row.fault) != row.fault)
        failInput(file, "$.fault",
                  "a one-line fault message of at most " + std::to_string(kMaxFaultBytes) +
                      " bytes without control characters");
      row.runMs.clear();
      const json& runMs = s.header.value("runMs", json());
      if (!runMs.is_array() || runMs.size() > size_t(plan.options.repeats))
        failInput(file, "$.runMs", "the times of at most " + std::to_string(plan.options.repeats) + " runs");
      for (const json& v : runMs) {
        const double ms = v.is_number_unsigned() ? fromBits(v.get<uint64_t>()) : -1;
        if (!(ms >= 0 && std::isfinite(ms))) failInput(file, "$.runMs", "the runs' times (finite, >= 0 ms)");
        row.runMs.push_back(ms);
      }
      row.summary = summaryFrom(s.header.value("summary", json()), file, plan);
      // A run that ended compared every common time and stepped; a faulted one may stop anywhere.
      if (row.fault.empty() &&
          (row.summary.ticks != plan.ticks / plan.interval + 1 || row.steps == 0 || row.runMs.empty()))
        failInput(file, "$.summary.ticks",
                  "a complete run's " + std::to_string(plan.ticks / plan.interval + 1) +
                      " compared times, its steps and its times");
    }
  } catch (const std::runtime_error& e) {
    *error = e.what();
    return false;
  }
  int64_t missing = 0, first = -1;
  for (int64_t j = 0; j < jobCount(plan); ++j)
    if (fileOf[size_t(j)].empty()) {
      if (first < 0) first = j;
      ++missing;
    }
  if (missing > 0) {
    *error = "job " + std::to_string(first) + " (" + jobName(plan, first) + "): missing from " + dir +
             (missing > 1 ? " (and " + std::to_string(missing - 1) + " more)" : "") + "; run it with --job " +
             std::to_string(first);
    return false;
  }
  return true;
}

}  // namespace sg::sweep
