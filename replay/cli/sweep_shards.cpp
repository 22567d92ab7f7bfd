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
          {"seconds", o.seconds},
          {"repeats", o.repeats},
          {"threads", o.threads}};
}

/// A one-line error about `file`: "file: where: expected what".
[[noreturn]] void fail(const std::string& file, const std::string& where, const std::string& what) {
  throw std::runtime_error(file + ": " + where + ": expected " + what);
}

template <class T>
T field(const json& j, const char* key, const std::string& file, const std::string& at) {
  const std::string where = at + "." + key;
  if (!j.is_object() || !j.contains(key)) fail(file, where, "a value (missing)");
  const json& v = j[key];
  if constexpr (std::is_same_v<T, std::string>) {
    if (!v.is_string()) fail(file, where, "a string");
  } else if constexpr (std::is_same_v<T, bool>) {
    if (!v.is_boolean()) fail(file, where, "true or false");
  } else if constexpr (std::is_floating_point_v<T>) {
    if (!v.is_number()) fail(file, where, "a number");
  } else {
    if (!v.is_number_integer()) fail(file, where, "an integer");
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
  o.seconds = field<double>(j, "seconds", file, at);
  o.repeats = int(field<int64_t>(j, "repeats", file, at));
  o.threads = int(field<int64_t>(j, "threads", file, at));
  if (!(o.seconds >= 1e-3 && o.seconds <= 3600)) fail(file, at + ".seconds", "1e-3 to 3600 s");
  if (o.repeats < 1 || o.repeats > 100) fail(file, at + ".repeats", "1 to 100");
  if (o.threads < 1 || o.threads > 256) fail(file, at + ".threads", "1 to 256");
  return o;
}

// ---- bytes ----------------------------------------------------------------------------------

/// Reads and checks a shard file. Throws std::runtime_error ("file: byte N: expected ...").
Shard readShard(const std::string& path, uint64_t maxPayload, bool withPayload = true) {
  std::vector<uint8_t> b;
  std::string expected;
  if (!readInputFile(path, InputLimits::kRecordingBytes, &b, &expected)) fail(path, "byte 0", expected);
  return parseShard(b, path, maxPayload, withPayload);
}

/// The most a reference payload of this plan can hold (a damaged size field cannot ask for more).
uint64_t maxPayloadBytes(const Plan& plan) {
  uint64_t most = 0;
  for (const ScenarioRun& sc : plan.scenarios) {
    const uint64_t patches = uint64_t(sc.reference.field.patchesX) * uint64_t(sc.reference.field.patchesZ);
    const uint64_t states = uint64_t(plan.ticks / plan.interval + 1);
    const uint64_t bodies = uint64_t(kMaxBodies);
    most = std::max(most, states * (48 + 8 * (3 * patches + 7 * bodies) + 40));
  }
  return most + InputLimits::kRecordingBytes;
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

DivergenceSummary summaryFrom(const json& j, const std::string& file) {
  const std::string at = "$.summary";
  DivergenceSummary s;
  s.ticks = field<int64_t>(j, "ticks", file, at);
  s.tipMax = fromBits(field<uint64_t>(j, "tipMax", file, at));
  s.tipMaxTick = field<int64_t>(j, "tipMaxTick", file, at);
  s.tipSumSquares = fromBits(field<uint64_t>(j, "tipSumSquares", file, at));
  s.bodyPosMax = fromBits(field<uint64_t>(j, "bodyPosMax", file, at));
  s.bodyAngleMax = fromBits(field<uint64_t>(j, "bodyAngleMax", file, at));
  s.contactDeltaMax = field<int64_t>(j, "contactDeltaMax", file, at);
  s.firstObservedTick = field<int64_t>(j, "firstObservedTick", file, at);
  s.firstHashTick = field<int64_t>(j, "firstHashTick", file, at);
  return s;
}

json modelErrorJson(const ModelError& e) { return {bitsOf(e.tipRms), bitsOf(e.tipMax), bitsOf(e.seconds)}; }

/// The reference results of scenario `s` from its shard's header and payload.
void takeReference(Plan& plan, size_t s, const Shard& shard, const std::string& file, bool withObservations) {
  ScenarioRun& sc = plan.scenarios[s];
  const json& h = shard.header;
  sc.patches = field<int64_t>(h, "patches", file, "$");
  sc.bodies = field<int64_t>(h, "bodies", file, "$");
  sc.statesCompared = field<int64_t>(h, "statesCompared", file, "$");
  const json& b = h.value("behaviour", json());
  sc.behaviour.swayStart = fromBits(field<uint64_t>(b, "swayStart", file, "$.behaviour"));
  sc.behaviour.swayLate = fromBits(field<uint64_t>(b, "swayLate", file, "$.behaviour"));
  sc.behaviour.settleAfterGust = fromBits(field<uint64_t>(b, "settleAfterGust", file, "$.behaviour"));
  sc.behaviour.settleAfterPress = fromBits(field<uint64_t>(b, "settleAfterPress", file, "$.behaviour"));
  sc.behaviour.downAfterPress = fromBits(field<uint64_t>(b, "downAfterPress", file, "$.behaviour"));
  const json& m = h.value("modelError", json());
  for (const Rational& dt : plan.axes.dts) {
    const std::string key = dt.toString();
    if (!m.is_object() || !m.contains(key) || !m[key].is_array() || m[key].size() != 3)
      fail(file, "$.modelError." + key, "three numbers (the model error at this dt)");
    for (const json& v : m[key])
      if (!v.is_number_unsigned()) fail(file, "$.modelError." + key, "three numbers (the model error at this dt)");
    sc.modelError[key] = {fromBits(m[key][0].get<uint64_t>()), fromBits(m[key][1].get<uint64_t>()),
                          fromBits(m[key][2].get<uint64_t>())};
  }
  for (Row& r : plan.rows)
    if (r.scenario == s) r.modelError = sc.modelError.at(r.settings.timeStep->toString());
  if (withObservations) readReferencePayload(shard.payload, file, &sc.recording, &sc.observed);
}

/// Checks that a shard belongs to this plan and is the job its header says; returns the job.
int64_t shardJob(const Plan& plan, const std::string& fingerprint, const Shard& s, const std::string& file) {
  if (s.header.value("format", std::string()) != kShardFormat)
    fail(file, "$.format", std::string("'") + kShardFormat + "'");
  const std::string theirs = s.header.value("fingerprint", std::string());
  if (theirs != fingerprint)
    fail(file, "$.fingerprint",
         "a shard of this plan (fingerprint " + fingerprint + "), got one of plan '" + theirs.substr(0, 40) + "'");
  const int64_t job = field<int64_t>(s.header, "job", file, "$");
  if (job < 0 || job >= jobCount(plan))
    fail(file, "$.job", "a job from 0 to " + std::to_string(jobCount(plan) - 1) + ", got " + std::to_string(job));
  const std::string kind = field<std::string>(s.header, "kind", file, "$");
  if (kind != (job < referenceJobs(plan) ? "reference" : "variant"))
    fail(file, "$.kind",
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
  const json doc = {{"format", kPlanFormat},
                    {"build", buildId()},
                    {"fingerprint", fingerprintOf(plan)},
                    {"options", optionsJson(plan.options)},
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

Plan readPlan(const std::string& path, std::string* fingerprint) {
  std::string text, expected;
  if (!readInputFile(path, kPlanBytes, &text, &expected)) fail(path, "$", expected);
  const json doc = json::parse(text, nullptr, false);
  if (!doc.is_object()) fail(path, "$", "a sweep plan (JSON, written by simgrass sweep --plan)");
  if (doc.value("format", std::string()) != kPlanFormat) fail(path, "$.format", std::string("'") + kPlanFormat + "'");
  const std::string build = field<std::string>(doc, "build", path, "$");
  if (build != buildId())
    fail(path, "$.build", "a plan of this build ('" + buildId() + "'), got '" + build.substr(0, 80) + "'");
  const Options o = optionsFrom(doc.value("options", json()), path);
  Plan plan;
  try {
    plan = makePlan(o, false);
  } catch (const std::exception& e) {  // ScenarioError, std::invalid_argument
    throw std::runtime_error(path + ": $.options: " + e.what());
  }
  const std::string want = field<std::string>(doc, "fingerprint", path, "$");
  *fingerprint = fingerprintOf(plan);
  if (want != *fingerprint)
    fail(path, "$.fingerprint",
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
      const Shard ref = readShard(refFile, maxPayloadBytes(plan));
      if (shardJob(plan, fingerprint, ref, refFile) != refJob) fail(refFile, "$.job", "job " + std::to_string(refJob));
      takeReference(plan, row.scenario, ref, refFile, true);
    } catch (const std::exception& e) {
      printError("simgrass sweep: job %" PRId64 " needs the reference shard of job %" PRId64 " (run it first): %s\n",
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
  // The plan beside the shards, for the merge (the same bytes from every job: a rewrite is harmless).
  const std::string planCopy = (fs::path(dir) / kPlanCopy).string();
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
  const uint64_t maxPayload = maxPayloadBytes(plan);
  try {
    for (const std::string& file : files) {
      // Headers first (a variant's result is its header); a reference's observations are not
      // needed by the report and stay in its payload.
      const Shard s = readShard(file, maxPayload, false);
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
      row.steps = field<int64_t>(s.header, "steps", file, "$");
      row.fault = field<std::string>(s.header, "fault", file, "$");
      row.runMs.clear();
      const json& runMs = s.header.value("runMs", json());
      if (!runMs.is_array() || runMs.size() > 100) fail(file, "$.runMs", "the runs' times (at most 100)");
      for (const json& v : runMs) {
        if (!v.is_number_unsigned()) fail(file, "$.runMs", "the runs' times");
        row.runMs.push_back(fromBits(v.get<uint64_t>()));
      }
      row.summary = summaryFrom(s.header.value("summary", json()), file);
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
